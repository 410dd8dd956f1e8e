#pragma once
/// \file PressureSolver.hpp
/// Preconditioned conjugate gradients for the symmetric positive definite pressure Poisson matrix of the
/// gas solver. Own loop (rather than Eigen::ConjugateGradient) for two reasons: the stopping test is on
/// the residual relative to a flux scale given by the caller (not to |b|, which is ~0 in a steady
/// state), and the incomplete-Cholesky factor may be reused while the matrix drifts (a factor of a
/// nearby SPD matrix is still a valid preconditioner), so it is not refactored every step.

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <memory>
#include <array>
#include <string>
#include <vector>

#include "cfddem/gas/AggregationMultigrid.hpp"

namespace rcfd::gas {

enum class Preconditioner { IncompleteCholesky, Jacobi, Multigrid };

/// Parses "ic", "jacobi" or "mg"; throws std::invalid_argument otherwise.
Preconditioner parsePreconditioner(const std::string& name);

struct PressureSolveStats {
  int iterations = 0;
  double residual = 0.0;  ///< |b - A x|_2 at exit [units of b]
  bool converged = false;
};

class PressureSolver {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  explicit PressureSolver(Preconditioner kind, int refactorInterval = 20);
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
  void applyPreconditioner(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;

  Preconditioner kind_;
  int refactorInterval_;
  int sinceFactor_ = 0;
  Matrix a_;
  Eigen::VectorXd inverseDiagonal_;
  struct IcHolder;
  std::unique_ptr<IcHolder> ic_;
  std::vector<std::array<int, 3>> cells_;
  std::unique_ptr<AggregationMultigrid> mg_;
};

}  // namespace rcfd::gas
