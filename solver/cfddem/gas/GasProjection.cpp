// GasSolver::project(): the pressure Poisson equation of the fractional step and the continuity
// residual, Eq. (1) (GasSolver.hpp).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "cfddem/gas/GasSolver.hpp"
#include "core/Errors.hpp"

namespace rcfd::gas {

// With q = p dt / rho and D_f = 1 / (1 + dt K_f) (implicit drag), the corrected face velocity is
// u_f = u*_f - D_f (q_hi - q_lo) / h, and Eq. (1) summed over the faces of a cell,
//   V phi dalpha/dt + sum_f A_f a_f alpha_f u_f . n_out = V s,
// gives sum_f c_f (q_c - q_nb) = V s - V phi dalpha/dt - sum_f A a alpha u* . n_out with
// c_f = A_f a_f alpha_f D_f / h (2 A a alpha / h at the outlet, where q = 0 half a cell away).
void GasSolver::project(double dt, const std::array<std::vector<double>, 3>& diag) {
  const auto n = grid_.shape;
  const Eigen::Vector3d h = grid_.spacing;
  const double area[3] = {h.y() * h.z(), h.x() * h.z(), h.x() * h.y()};
  const double vol = grid_.cellVolume();
  const int unknowns = int(q_.size());
  Eigen::VectorXd b = Eigen::VectorXd::Zero(unknowns), scale = Eigen::VectorXd::Zero(unknowns);
  // The matrix depends on alpha_G and on the drag factor D (with dt): rebuilt only when those may have
  // changed.
  const bool rebuild = matrixDirty_ || hasDrag_ || pressureSolver_->matrix().rows() != unknowns;
  std::vector<Eigen::Triplet<double>> triplets;
  if (rebuild) triplets.reserve(std::size_t(unknowns) * 7);
  for (std::size_t c = 0; c < alpha_.size(); ++c) {
    const int r = unknown_[c];
    if (r < 0) continue;
    const double storage = vol * phi_[c] * dAlphaDt_[c];
    b[r] += vol * source_[c] - storage;
    scale[r] += std::abs(vol * source_[c]) + std::abs(storage);
  }
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) {
          const std::size_t f = faceIndex(d, i, j, k);
          const char kind = kind_[std::size_t(d)][f];
          if (kind == Closed) continue;
          const double aaa = area[d] * ap_.open[std::size_t(d)][f] * faceAlpha(d, f, i, j, k);
          const double flux = aaa * u_[std::size_t(d)][f];  // along +d
          std::array<int, 3> lo{i, j, k};
          lo[std::size_t(d)] -= 1;
          const int rLo = lo[std::size_t(d)] >= 0 ? unknown_[std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]))] : -1;
          const int rHi = i < n[0] && j < n[1] && k < n[2] ? unknown_[std::size_t(grid_.flatIndex(i, j, k))] : -1;
          if (rLo >= 0) b[rLo] -= flux, scale[rLo] += std::abs(flux);
          if (rHi >= 0) b[rHi] += flux, scale[rHi] += std::abs(flux);
          if (!rebuild) continue;
          if (kind == Interior) {
            const double cf = aaa * diag[std::size_t(d)][f] / h[d];
            triplets.emplace_back(rLo, rLo, cf);
            triplets.emplace_back(rHi, rHi, cf);
            triplets.emplace_back(rLo, rHi, -cf);
            triplets.emplace_back(rHi, rLo, -cf);
          } else if (kind == Outlet) {
            triplets.emplace_back(rLo, rLo, 2 * aaa / h[d]);
          }
        }
  }
  if (rebuild) {
    PressureSolver::Matrix m(unknowns, unknowns);
    m.setFromTriplets(triplets.begin(), triplets.end());
    // Unchanged values (alpha_G set again to the same field) keep the preconditioner.
    const bool same = m.nonZeros() == pressureSolver_->matrix().nonZeros() &&
                      m.rows() == pressureSolver_->matrix().rows() &&
                      Eigen::Map<const Eigen::VectorXd>(m.valuePtr(), m.nonZeros()) ==
                          Eigen::Map<const Eigen::VectorXd>(pressureSolver_->matrix().valuePtr(), m.nonZeros());
    if (!same) pressureSolver_->setMatrix(m);
    matrixDirty_ = false;
  }
  // Warm start from the last pressure, rescaled to this dt (q = p dt / rho).
  const double rho = scene_.gas.density;
  for (std::size_t c = 0; c < alpha_.size(); ++c)
    if (unknown_[c] >= 0) q_[unknown_[c]] = p_[c] * dt / rho;
  // Stop at half the tolerance on the predicted flux scale; the check after the correction is against
  // the corrected fluxes, which may be smaller: if it fails, iterate further from where CG stopped.
  const double tol = scene_.gas.pressure_tolerance;
  double absTol = 0.5 * tol * scale.norm();
  const std::array<std::vector<double>, 3> predicted = u_;
  last_.pressureIterations = 0;
  for (int attempt = 0; attempt < 4; ++attempt) {
    const auto stats = pressureSolver_->solve(b, q_, absTol, options_.maxPressureIterations);
    last_.pressureIterations += stats.iterations;
    if (!stats.converged)
      throw RunError("gas solver: the pressure solver did not converge in " + std::to_string(stats.iterations) +
                     " iterations (residual " + std::to_string(stats.residual / std::max(scale.norm(), 1e-300)) +
                     " of the flux scale, tolerance /gas/pressure_tolerance = " + std::to_string(tol) + ")");
    u_ = predicted;
    correct(diag);
    last_.divergence = divergence(dt);
    if (last_.divergence.relative <= tol) break;
    absTol *= 0.5 * tol / last_.divergence.relative;
  }
  for (std::size_t c = 0; c < alpha_.size(); ++c) p_[c] = unknown_[c] >= 0 ? q_[unknown_[c]] * rho / dt : 0.0;
}

// Corrects the face velocities with the pressure gradient: u = u* - D (q_hi - q_lo) / h.
void GasSolver::correct(const std::array<std::vector<double>, 3>& diag) {
  const Eigen::Vector3d h = grid_.spacing;
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    auto& ud = u_[std::size_t(d)];
#pragma omp parallel for collapse(2) schedule(static) if (ud.size() > 100000)
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) {
          const std::size_t f = faceIndex(d, i, j, k);
          const char kind = kind_[std::size_t(d)][f];
          if (kind != Interior && kind != Outlet) continue;
          std::array<int, 3> lo{i, j, k};
          lo[std::size_t(d)] -= 1;
          const double qLo = q_[unknown_[std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]))]];
          if (kind == Interior) {
            const double qHi = q_[unknown_[std::size_t(grid_.flatIndex(i, j, k))]];
            ud[f] -= diag[std::size_t(d)][f] * (qHi - qLo) / h[d];
          } else {
            ud[f] -= (0.0 - qLo) / (0.5 * h[d]);
          }
        }
  }
}

DivergenceResidual GasSolver::divergence(double dt) const {
  (void)dt;
  const auto n = grid_.shape;
  const Eigen::Vector3d h = grid_.spacing;
  const double area[3] = {h.y() * h.z(), h.x() * h.z(), h.x() * h.y()};
  const double vol = grid_.cellVolume();
  std::vector<double> r(alpha_.size(), 0.0), scale(alpha_.size(), 0.0);
  for (std::size_t c = 0; c < alpha_.size(); ++c) {
    if (!active_[c]) continue;
    const double storage = vol * phi_[c] * dAlphaDt_[c];
    r[c] = storage - vol * source_[c];
    scale[c] = std::abs(storage) + vol * std::abs(source_[c]);
  }
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) {
          const std::size_t f = faceIndex(d, i, j, k);
          if (kind_[std::size_t(d)][f] == Closed) continue;
          const double flux = area[d] * ap_.open[std::size_t(d)][f] * faceAlpha(d, f, i, j, k) * u_[std::size_t(d)][f];
          std::array<int, 3> lo{i, j, k};
          lo[std::size_t(d)] -= 1;
          if (lo[std::size_t(d)] >= 0) {
            const std::size_t c = std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]));
            r[c] += flux, scale[c] += std::abs(flux);
          }
          if (i < n[0] && j < n[1] && k < n[2]) {
            const std::size_t c = std::size_t(grid_.flatIndex(i, j, k));
            r[c] -= flux, scale[c] += std::abs(flux);
          }
        }
  }
  DivergenceResidual out;
  double rr = 0.0, ss = 0.0;
  for (std::size_t c = 0; c < r.size(); ++c) {
    if (!active_[c]) continue;
    rr += r[c] * r[c];
    ss += scale[c] * scale[c];
    out.maxAbs = std::max(out.maxAbs, std::abs(r[c]) / vol);
  }
  out.relative = ss > 0 ? std::sqrt(rr / ss) : 0.0;
  return out;
}

}  // namespace rcfd::gas
