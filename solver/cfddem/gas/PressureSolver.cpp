// Preconditioned conjugate gradients for the pressure equation (declared in PressureSolver.hpp).

#include "cfddem/gas/PressureSolver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rcfd::gas {

PressureSolver::PressureSolver(std::unique_ptr<PressurePreconditioner> preconditioner, int refactorInterval)
    : preconditioner_(std::move(preconditioner)), refactorInterval_(refactorInterval) {}

PressureSolver::~PressureSolver() = default;

void PressureSolver::setCells(std::vector<std::array<int, 3>> cellOf) {
  preconditioner_->setCells(cellOf);
  built_ = false;
}

void PressureSolver::setMatrix(const Matrix& a, bool force) {
  const bool newPattern = a.rows() != a_.rows() || a.nonZeros() != a_.nonZeros();
  a_ = a;
  if (!built_ || !preconditioner_->reusable() || newPattern || force || ++sinceFactor_ >= refactorInterval_) {
    preconditioner_->build(a_);
    built_ = true;
    sinceFactor_ = 0;
  }
}

namespace {

/// y = A x with the rows split over the OpenMP threads (Eigen runs sparse products serially).
void multiply(const PressureSolver::Matrix& a, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const int n = int(a.rows());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* val = a.valuePtr();
#pragma omp parallel for schedule(static) if (n >= kParallelPressureRows)
  for (int r = 0; r < n; ++r) {
    double s = 0.0;
    for (int q = outer[r]; q < outer[r + 1]; ++q) s += val[q] * x[inner[q]];
    y[r] = s;
  }
}

/// Dot product summed in fixed blocks whose partial sums are added in block order: the same bits for
/// any number of threads (an OpenMP reduction sums in a thread-dependent order, which would make the
/// coupled CFD-DEM depend on the thread count).
constexpr long kDotBlock = 2048;
double dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const long n = a.size();
  const long blocks = (n + kDotBlock - 1) / kDotBlock;
  std::vector<double> partial(std::size_t(std::max(blocks, 1L)), 0.0);
#pragma omp parallel for schedule(static) if (n >= kParallelPressureRows)
  for (long k = 0; k < blocks; ++k) {
    double s = 0.0;
    const long end = std::min(n, (k + 1) * kDotBlock);
    for (long i = k * kDotBlock; i < end; ++i) s += a[i] * b[i];
    partial[std::size_t(k)] = s;
  }
  double s = 0.0;
  for (double p : partial) s += p;
  return s;
}

}  // namespace

PressureSolveStats PressureSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x, double absTol,
                                         int maxIterations) {
  PressureSolveStats stats;
  const long n = b.size();
  Eigen::VectorXd r(n), z(n), p(n), q(n);
  multiply(a_, x, q);
  r = b - q;
  double rr = dot(r, r);
  stats.residual = std::sqrt(rr);
  if (stats.residual <= absTol) {
    stats.converged = true;
    return stats;
  }
  preconditioner_->apply(r, z);
  p = z;
  double rz = dot(r, z);
  for (int it = 1; it <= maxIterations; ++it) {
    multiply(a_, p, q);
    const double alpha = rz / dot(p, q);
    x += alpha * p;
    r -= alpha * q;
    rr = dot(r, r);
    stats.iterations = it;
    stats.residual = std::sqrt(rr);
    if (!std::isfinite(stats.residual)) return stats;
    if (stats.residual <= absTol) {
      // The recursive residual drifts from the true one over many iterations: confirm it.
      multiply(a_, x, q);
      r = b - q;
      stats.residual = r.norm();
      if (stats.residual <= absTol) {
        stats.converged = true;
        return stats;
      }
    }
    preconditioner_->apply(r, z);
    const double rzNew = dot(r, z);
    p = z + (rzNew / rz) * p;
    rz = rzNew;
  }
  return stats;
}

}  // namespace rcfd::gas
