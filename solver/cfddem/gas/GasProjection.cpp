// GasSolver::project(): the pressure Poisson equation of the fractional step and the continuity
// residual, Eq. (1) (GasSolver.hpp).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
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
  const Eigen::Vector3d h = grid_.spacing;
  const double vol = grid_.cellVolume();
  const int unknowns = int(q_.size());
  Eigen::VectorXd b = Eigen::VectorXd::Zero(unknowns), scale = Eigen::VectorXd::Zero(unknowns);
  // The matrix depends on alpha_G and on the drag factor D (with dt): rebuilt only when those may have
  // changed.
  const bool rebuild = matrixDirty_ || hasDrag_ || pressureSolver_->matrix().rows() != unknowns;
  if (rebuild) {
    if (matrix_.rows() != unknowns) buildMatrixPattern();
    std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
  }
  computeGasAreas();
  double* const values = matrix_.valuePtr();
  // Each cell gathers its own row (b, scale and the matrix's row) from its faces, in the order a scatter
  // over the faces (axis by axis, x fastest) would add them: the same sums for any number of threads.
  // A face's lower cell subtracts its flux, its upper cell adds it.
  const auto n = grid_.shape;
#pragma omp parallel for collapse(2) schedule(static) if (alpha_.size() > kParallelFaces)
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const std::size_t c = std::size_t(grid_.flatIndex(i, j, k));
        const int r = unknown_[c];
        if (r < 0) continue;
        const double storage = vol * phi_[c] * dAlphaDt_[c];
        double bc = 0.0 + (vol * source_[c] - storage);
        double sc = 0.0 + (std::abs(vol * source_[c]) + std::abs(storage));
        forEachOpenFaceOf(i, j, k, [&](int d, std::size_t f, bool upperCell) {
          const double flux = gasArea_[std::size_t(d)][f] * u_[std::size_t(d)][f];
          bc += upperCell ? flux : -flux, sc += std::abs(flux);
          if (!rebuild) return;
          const char kind = kind_[std::size_t(d)][f];
          const auto& slot = matrixSlot_[std::size_t(d)][f];
          if (kind == Interior) {
            const double cf = gasArea_[std::size_t(d)][f] * diag[std::size_t(d)][f] / h[d];
            values[slot[upperCell ? 1 : 0]] += cf;  // (hi, hi) or (lo, lo)
            values[slot[upperCell ? 3 : 2]] -= cf;  // (hi, lo) or (lo, hi)
          } else if (kind == Outlet && !upperCell) {
            values[slot[0]] += 2 * gasArea_[std::size_t(d)][f] / h[d];
          }
        });
        b[r] = bc, scale[r] = sc;
      }
  if (rebuild) {
    const PressureSolver::Matrix& m = matrix_;
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
    if (!stats.converged) {
      std::ostringstream m;
      m.precision(3);
      m << "gas solver: the pressure solver did not converge in " << stats.iterations << " iterations (relative residual "
        << stats.residual / std::max(scale.norm(), 1e-300) << ", goal " << absTol / std::max(scale.norm(), 1e-300)
        << " from the tolerance /gas/pressure_tolerance = " << tol
        << "; a tolerance near the solver's round-off floor, which cells of a large aspect ratio raise, needs "
           "loosening)";
      throw RunError(m.str());
    }
    u_ = predicted;
    correct(diag);
    last_.divergence = divergence();
    const double worst = std::max(last_.divergence.relative, last_.divergence.net);
    if (worst <= tol) break;
    absTol *= 0.5 * tol / worst;
  }
  for (std::size_t c = 0; c < alpha_.size(); ++c) p_[c] = unknown_[c] >= 0 ? q_[unknown_[c]] * rho / dt : 0.0;
  updatePressureGradient();
}

// The matrix's sparsity follows the topology alone (which faces are interior or outlet), so it is set
// up once; each rebuild refills the values in place through the faces' slots, in the order the faces
// are visited (the sums of the diagonal are those a triplet assembly would form).
void GasSolver::buildMatrixPattern() {
  const int unknowns = int(q_.size());
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(std::size_t(unknowns) * 7);
  forEachFace([&](int d, int i, int j, int k, std::size_t f) {
    const char kind = kind_[std::size_t(d)][f];
    const auto [rLo, rHi] = faceUnknowns(d, i, j, k);
    if (kind == Interior) {
      for (const auto& [r, c] : {std::pair{rLo, rLo}, {rHi, rHi}, {rLo, rHi}, {rHi, rLo}}) triplets.emplace_back(r, c, 1.0);
    } else if (kind == Outlet) {
      triplets.emplace_back(rLo, rLo, 1.0);
    }
  });
  matrix_ = PressureSolver::Matrix(unknowns, unknowns);
  matrix_.setFromTriplets(triplets.begin(), triplets.end());
  matrix_.makeCompressed();
  auto slotOf = [&](int row, int col) {
    const int* inner = matrix_.innerIndexPtr();
    const int* begin = inner + matrix_.outerIndexPtr()[row];
    const int* end = inner + matrix_.outerIndexPtr()[row + 1];
    return int(std::lower_bound(begin, end, col) - inner);
  };
  for (int d = 0; d < 3; ++d) matrixSlot_[std::size_t(d)].assign(kind_[std::size_t(d)].size(), {0, 0, 0, 0});
  forEachFace([&](int d, int i, int j, int k, std::size_t f) {
    const char kind = kind_[std::size_t(d)][f];
    const auto [rLo, rHi] = faceUnknowns(d, i, j, k);
    auto& slot = matrixSlot_[std::size_t(d)][f];
    if (kind == Interior) slot = {slotOf(rLo, rLo), slotOf(rHi, rHi), slotOf(rLo, rHi), slotOf(rHi, rLo)};
    else if (kind == Outlet) slot[0] = slotOf(rLo, rLo);
  });
}

std::array<int, 2> GasSolver::faceUnknowns(int d, int i, int j, int k) const {
  const auto n = grid_.shape;
  std::array<int, 3> lo{i, j, k};
  lo[std::size_t(d)] -= 1;
  const int rLo = lo[std::size_t(d)] >= 0 ? unknown_[std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]))] : -1;
  const int rHi = i < n[0] && j < n[1] && k < n[2] ? unknown_[std::size_t(grid_.flatIndex(i, j, k))] : -1;
  return {rLo, rHi};
}

// Corrects the face velocities with the pressure gradient: u = u* - D (q_hi - q_lo) / h.
void GasSolver::correct(const std::array<std::vector<double>, 3>& diag) {
  const Eigen::Vector3d h = grid_.spacing;
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    auto& ud = u_[std::size_t(d)];
#pragma omp parallel for collapse(2) schedule(static) if (ud.size() > kParallelFaces)
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

void GasSolver::computeGasAreas() {
  const Eigen::Vector3d h = grid_.spacing;
  const double area[3] = {h.y() * h.z(), h.x() * h.z(), h.x() * h.y()};
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    auto& out = gasArea_[std::size_t(d)];
    out.resize(kind_[std::size_t(d)].size());
#pragma omp parallel for collapse(2) schedule(static) if (out.size() > kParallelFaces)
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) {
          const std::size_t f = faceIndex(d, i, j, k);
          out[f] = kind_[std::size_t(d)][f] == Closed ? 0.0 : area[d] * ap_.open[std::size_t(d)][f] * faceAlpha(d, f, i, j, k);
        }
  }
}

DivergenceResidual GasSolver::divergence() const {
  const auto n = grid_.shape;
  const double vol = grid_.cellVolume();
  std::vector<double>& r = divergenceScratch_[0];
  std::vector<double>& scale = divergenceScratch_[1];
  r.assign(alpha_.size(), 0.0), scale.assign(alpha_.size(), 0.0);
  // Gathered per cell in the order of a scatter over the faces (as the assembly in project()): a face's
  // lower cell gains its flux, its upper cell loses it.
#pragma omp parallel for collapse(2) schedule(static) if (alpha_.size() > kParallelFaces)
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const std::size_t c = std::size_t(grid_.flatIndex(i, j, k));
        if (!active_[c]) continue;
        const double storage = vol * phi_[c] * dAlphaDt_[c];
        double rc = 0.0 + (storage - vol * source_[c]);
        double sc = 0.0 + (std::abs(storage) + vol * std::abs(source_[c]));
        forEachOpenFaceOf(i, j, k, [&](int d, std::size_t f, bool upperCell) {
          const double flux = gasArea_[std::size_t(d)][f] * u_[std::size_t(d)][f];
          rc += upperCell ? -flux : flux, sc += std::abs(flux);
        });
        r[c] = rc, scale[c] = sc;
      }
  double supply = 0.0, stored = 0.0;  // gas fed (inlet, nozzle) and sum |storage| [m3/s]
  for (std::size_t c = 0; c < alpha_.size(); ++c) {
    if (!active_[c]) continue;
    supply += vol * std::abs(source_[c]);
    stored += std::abs(vol * phi_[c] * dAlphaDt_[c]);
  }
  for (const auto& [d, f] : inletFaces_) supply += std::abs(gasArea_[std::size_t(d)][f] * u_[std::size_t(d)][f]);
  DivergenceResidual out;
  double rr = 0.0, ss = 0.0, sum = 0.0;
  std::size_t cells = 0;
  for (std::size_t c = 0; c < r.size(); ++c) {
    if (!active_[c]) continue;
    ++cells;
    sum += r[c];
    rr += r[c] * r[c];
    ss += scale[c] * scale[c];
    out.maxAbs = std::max(out.maxAbs, std::abs(r[c]) / vol);
  }
  // Both measures are relative to the step's own fluxes, but never to less than a millionth of the
  // scene's full gas flow: a gas at rest (no flow yet at the start of the ramp, no drag to stir it) has
  // only round-off fluxes, whose residuals are as large as themselves.
  const double least = 1e-6 * (scene_.process.gas_flow_rate + scene_.process.atomisation_flow_rate);
  out.relative = ss > 0 ? std::sqrt(rr / std::max(ss, least * least)) : 0.0;
  // Relative to the gas fed; without a feed (gas moved only by alpha_G), to what is stored; and never to
  // less than the cells' root-mean-square flux: at the start of a ramp nothing is fed yet while the
  // drag of moving parcels stirs the gas, and a balance relative to a feed of 0 cannot be met.
  const double rmsCell = cells > 0 ? std::sqrt(ss / double(cells)) : 0.0;
  const double netScale = std::max({supply > 0 ? supply : stored, least, rmsCell});
  out.net = netScale > 0 ? std::abs(sum) / netScale : 0.0;
  return out;
}

}  // namespace rcfd::gas
