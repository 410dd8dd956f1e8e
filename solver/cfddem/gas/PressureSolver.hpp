#pragma once
/// \file PressureSolver.hpp
/// Preconditioned conjugate gradients for the symmetric positive definite pressure Poisson matrix of the
/// gas solver. Own loop (rather than Eigen::ConjugateGradient) for two reasons: the stopping test is on
/// the residual relative to a flux scale given by the caller (not to |b|, which is ~0 in a steady
/// state), and a preconditioner's factor may be reused while the matrix drifts (a factor of a nearby
/// SPD matrix is still a valid preconditioner), so it is not refactored every step.

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <memory>
#include <array>
#include <string>
#include <vector>

#include "cfddem/gas/AggregationMultigrid.hpp"
#include "core/Registry.hpp"

namespace rcfd::gas {

/// A preconditioner M of the pressure CG, selected by the scene's gas.pressure_preconditioner:
/// "mg", "ic" and "jacobi" (PressurePreconditioners.cpp; docs/gas.md, "Pressure solver choice").
class PressurePreconditioner {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  virtual ~PressurePreconditioner() = default;
  /// True if what build() computes stays a valid preconditioner while the matrix drifts: PressureSolver
  /// then rebuilds it only every refactorInterval new matrices; false: at every new matrix.
  virtual bool reusable() const = 0;
  /// The grid cell (i, j, k) of every unknown, before the first build(); geometric methods use them.
  virtual void setCells(const std::vector<std::array<int, 3>>& /*cellOf*/) {}
  /// Builds M for the matrix A.
  virtual void build(const Matrix& a) = 0;
  /// z = M^-1 r.
  virtual void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const = 0;
};

using PreconditionerRegistry = Registry<PressurePreconditioner>;

struct PressureSolveStats {
  int iterations = 0;
  double residual = 0.0;  ///< |b - A x|_2 at exit [units of b]
  bool converged = false;
};

class PressureSolver {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  explicit PressureSolver(std::unique_ptr<PressurePreconditioner> preconditioner, int refactorInterval = 20);
  ~PressureSolver();

  /// Takes a new matrix (same sparsity pattern from step to step). The preconditioner is rebuilt when
  /// the pattern changes, when `force`, or after refactorInterval calls.
  void setMatrix(const Matrix& a, bool force = false);

  /// Solves A x = b starting from x (warm start) until |b - A x|_2 <= absTol or maxIterations.
  PressureSolveStats solve(const Eigen::VectorXd& b, Eigen::VectorXd& x, double absTol, int maxIterations);

  const Matrix& matrix() const { return a_; }

  /// The grid cell (i, j, k) of every unknown: the multigrid's aggregates. Call before setMatrix().
  void setCells(std::vector<std::array<int, 3>> cellOf);

 private:
  std::unique_ptr<PressurePreconditioner> preconditioner_;
  bool built_ = false;
  int refactorInterval_;
  int sinceFactor_ = 0;
  Matrix a_;
};

}  // namespace rcfd::gas
