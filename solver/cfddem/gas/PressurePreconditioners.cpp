// The preconditioners of the pressure CG, registered by name (PressureSolver.hpp; docs/gas.md,
// "Pressure solver choice"): "mg" (the default), "ic" and "jacobi".

#include <Eigen/IterativeLinearSolvers>
#include <stdexcept>

#include "cfddem/gas/AggregationMultigrid.hpp"
#include "cfddem/gas/PressureSolver.hpp"

namespace rcfd::gas {
namespace {

/// The aggregation multigrid V-cycle (AggregationMultigrid.hpp): iteration counts nearly independent of
/// the grid. Its aggregates follow the unknowns' cells, so it is made again when they change.
class MultigridPreconditioner final : public PressurePreconditioner {
 public:
  bool reusable() const override { return true; }
  void setCells(const std::vector<std::array<int, 3>>& cellOf) override {
    cells_ = cellOf;
    mg_.reset();
  }
  void build(const Matrix& a) override {
    if (cells_.size() != std::size_t(a.rows())) throw std::logic_error("multigrid: setCells() not called");
    if (!mg_) mg_ = std::make_unique<AggregationMultigrid>(cells_);
    mg_->compute(a);
  }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { mg_->apply(r, z); }

 private:
  std::vector<std::array<int, 3>> cells_;
  std::unique_ptr<AggregationMultigrid> mg_;
};

/// Eigen's incomplete Cholesky. Natural ordering keeps the lexicographic order of the grid, for which IC
/// works well on a 7-point Laplacian; Eigen adds a diagonal shift by itself if a pivot turns non-positive.
class IncompleteCholeskyPreconditioner final : public PressurePreconditioner {
 public:
  bool reusable() const override { return true; }
  void build(const Matrix& a) override {
    const Eigen::SparseMatrix<double> colMajor = a;
    factor_.compute(colMajor);
    if (factor_.info() != Eigen::Success) throw std::runtime_error("incomplete Cholesky of the pressure matrix failed");
  }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { z = factor_.solve(r); }

 private:
  Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::NaturalOrdering<int>> factor_;
};

/// The inverse diagonal: cheap to build, so it follows every new matrix.
class JacobiPreconditioner final : public PressurePreconditioner {
 public:
  bool reusable() const override { return false; }
  void build(const Matrix& a) override { inverseDiagonal_ = a.diagonal().cwiseInverse(); }
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { z = inverseDiagonal_.cwiseProduct(r); }

 private:
  Eigen::VectorXd inverseDiagonal_;
};

const bool mgRegistered = PreconditionerRegistry::add(
    "mg", "aggregation multigrid V-cycle (2x2x2 aggregates, Galerkin levels, symmetric Gauss-Seidel)",
    [] { return std::make_unique<MultigridPreconditioner>(); });
const bool icRegistered = PreconditionerRegistry::add(
    "ic", "incomplete Cholesky (Eigen, natural ordering)",
    [] { return std::make_unique<IncompleteCholeskyPreconditioner>(); });
const bool jacobiRegistered = PreconditionerRegistry::add(
    "jacobi", "the inverse diagonal", [] { return std::make_unique<JacobiPreconditioner>(); });

}  // namespace
}  // namespace rcfd::gas
