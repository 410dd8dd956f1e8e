// GasSolver: the explicit rates of the predictor, advection + viscosity + explicit sources of Eq. (2)
// on the staggered faces (GasSolver.hpp; the scheme in docs/gas.md).
//
// The stencil of a face value reaches two faces either way along each axis. Where it leaves the grid
// the value comes from a ghost (mirror or copy, GhostPoint); which one depends only on the axis pair
// and the face's index along the stencil's axis, so buildStencils() tabulates it once and the rates
// loop does no index arithmetic beyond a lookup. In a thin slice (4 cells deep) every stencil along z
// leaves the grid, which made the per-point ghost search the largest cost of the gas phase.

#include <algorithm>

#include "cfddem/gas/GasSolver.hpp"

namespace rcfd::gas {
namespace {

/// van Leer limited slope from the two one-sided differences (0 at an extremum).
inline double limitedSlope(double forward, double backward) {
  const double prod = forward * backward;
  return prod > 0.0 ? 2.0 * prod / (forward + backward) : 0.0;
}

/// Adds to r the advection and viscosity of one axis at a face, Eq. (2): -a dphi/dx by second-order
/// upwind with a van Leer limiter (first order at extrema) from limited values at the two half-points,
/// and nu d2phi/dx2; w0..w4 are the face values at offsets -2..2 along the axis, h its spacing. Both
/// upwind sides are formed and one selected, so a loop over faces stays branch-free.
inline double addAdvectionDiffusion(double r, double a, double w0, double w1, double w2, double w3, double w4,
                                    double h, double nu) {
  const double plusUp = w2 + 0.5 * limitedSlope(w3 - w2, w2 - w1);
  const double minusUp = w1 + 0.5 * limitedSlope(w2 - w1, w1 - w0);
  const double plusDown = w3 - 0.5 * limitedSlope(w4 - w3, w3 - w2);
  const double minusDown = w2 - 0.5 * limitedSlope(w3 - w2, w2 - w1);
  const bool up = a >= 0;
  const double plus = up ? plusUp : plusDown, minus = up ? minusUp : minusDown;
  r -= a * (plus - minus) / h;
  r += nu * (w3 - 2 * w2 + w1) / (h * h);  // alpha grad.tau / (alpha rho)
  return r;
}

/// Adds to r a face's body and source terms: gravity, the explicit force per volume fe over
/// (alpha rho), and the nozzle air entering with the jet velocity (+y), s (u_jet - u) / alpha.
inline double addSources(double r, double gravity, double fe, double sF, double jet, double u, double aF,
                         double rho) {
  return r + gravity + fe / (aF * rho) + sF * (jet - u) / aF;
}

}  // namespace

void GasSolver::buildStencils() {
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    for (int e = 0; e < 3; ++e) {
      // Out-of-range neighbours along e of a face value of axis d. Along d: the boundary face itself.
      // Across: a mirror image, odd (no-slip wall, inlet with no tangential velocity), even (slip
      // front/back or side walls) or a copy (zero gradient at the outlet on top).
      const int nE = s[std::size_t(e)];
      const bool slip = (e == 2 && options_.slipFrontBack) || (e == 0 && options_.slipSideWalls);
      auto& table = ghost_[std::size_t(d)][std::size_t(e)];
      table.assign(std::size_t(nE) * 5, GhostPoint{});
      for (int x = 0; x < nE; ++x)
        for (int m = -2; m <= 2; ++m) {
          int q = x + m;
          double sign = 1.0;
          if (q < 0 || q >= nE) {
            const bool high = q >= nE;
            if (e == d) {
              q = std::clamp(q, 0, nE - 1);
            } else if (e == 1 && high) {
              q = nE - 1;
            } else {
              q = std::clamp(high ? 2 * nE - 1 - q : -1 - q, 0, nE - 1);
              if (!slip) sign = -1.0;
            }
          }
          table[std::size_t(x) * 5 + std::size_t(m + 2)] = GhostPoint{q - x, sign};
        }
    }
    // Faces whose stencil across some axis e meets a baffle: bit e set (mirrorAtBaffles applies).
    auto& mask = nearBaffle_[std::size_t(d)];
    mask.clear();
    if (ap_.baffles.empty()) continue;
    mask.assign(ap_.open[std::size_t(d)].size(), 0);
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i)
          for (int e = 0; e < 3; ++e) {
            if (e == d) continue;
            bool near = false;
            for (int m = -2; m <= 1 && !near; ++m) {
              std::array<int, 3> q{i, j, k};
              q[std::size_t(e)] += m;
              near = baffleAhead(d, e, q);
            }
            if (near) mask[faceIndex(d, i, j, k)] |= std::uint8_t(1u << e);
          }
  }
}

bool GasSolver::baffleAhead(int d, int e, std::array<int, 3> idx) const {
  // Face idx of axis d lies between cells idx - e_d and idx; a step along +e leaves both cells through
  // their e-faces at index + 1: a baffle when it closes both (a plate tip closing one is no wall).
  if (idx[std::size_t(e)] < 0 || idx[std::size_t(e)] >= grid_.shape[std::size_t(e)]) return false;
  idx[std::size_t(e)] += 1;
  std::array<int, 3> lo = idx;
  lo[std::size_t(d)] -= 1;
  return ap_.baffles.closes(e, idx[0], idx[1], idx[2]) && ap_.baffles.closes(e, lo[0], lo[1], lo[2]);
}

void GasSolver::mirrorAtBaffles(int d, int e, const std::array<int, 3>& idx, double v[5]) const {
  // A baffle lies midway between two neighbouring face values of axis d along e != d: the values behind
  // it are replaced by the odd mirror image of those in front (no-slip, as at the outer walls), so no
  // momentum is advected or diffused through a plate.
  auto shifted = [&](int m) {
    std::array<int, 3> q = idx;
    q[std::size_t(e)] += m;
    return q;
  };
  if (baffleAhead(d, e, idx)) {
    v[3] = -v[2], v[4] = -v[1];
  } else if (baffleAhead(d, e, shifted(1))) {
    v[4] = -v[3];
  }
  if (baffleAhead(d, e, shifted(-1))) {
    v[1] = -v[2], v[0] = -v[3];
  } else if (baffleAhead(d, e, shifted(-2))) {
    v[0] = -v[1];
  }
}

double GasSolver::faceRate(const std::array<std::vector<double>, 3>& u, int d, int i, int j, int k) const {
  const std::size_t f = faceIndex(d, i, j, k);
  if (kind_[std::size_t(d)][f] != Interior) return 0.0;
  const Eigen::Vector3d h = grid_.spacing;
  const double nu = scene_.gas.kinematic_viscosity, rho = scene_.gas.density;
  const auto& ud = u[std::size_t(d)];
  const int idx[3] = {i, j, k};
  double r = 0.0;
  for (int e = 0; e < 3; ++e) {
    // Transport velocity component e at this face: itself along d, else the mean of the four e-faces
    // of the two cells beside the face (the MAC average).
    double a;
    if (e == d) {
      a = ud[f];
    } else {
      const auto& ue = u[std::size_t(e)];
      const auto& se = ap_.shape[std::size_t(e)];
      const std::ptrdiff_t stride[3] = {1, se[0], std::ptrdiff_t(se[0]) * se[1]};
      const std::ptrdiff_t fe = k * stride[2] + j * stride[1] + i, lo = fe - stride[d];
      a = 0.25 * (ue[std::size_t(fe)] + ue[std::size_t(fe + stride[e])] + ue[std::size_t(lo)] +
                  ue[std::size_t(lo + stride[e])]);
    }
    double v[5];  // offsets -2 .. +2 along e
    const GhostPoint* g = &ghost_[std::size_t(d)][std::size_t(e)][std::size_t(idx[e]) * 5];
    const auto& sd = ap_.shape[std::size_t(d)];
    const std::ptrdiff_t step = e == 0 ? 1 : e == 1 ? sd[0] : std::ptrdiff_t(sd[0]) * sd[1];
    for (int m = 0; m < 5; ++m) v[m] = g[m].sign * ud[std::size_t(std::ptrdiff_t(f) + g[m].shift * step)];
    if (!nearBaffle_[std::size_t(d)].empty() && (nearBaffle_[std::size_t(d)][f] >> e & 1u))
      mirrorAtBaffles(d, e, {i, j, k}, v);
    r = addAdvectionDiffusion(r, a, v[0], v[1], v[2], v[3], v[4], h[e], nu);
  }
  const auto n = grid_.shape;
  const std::size_t ch = std::size_t(grid_.flatIndex(i, j, k));
  const std::size_t cl = ch - std::size_t(d == 0 ? 1 : d == 1 ? n[0] : std::ptrdiff_t(n[0]) * n[1]);
  const double aF = 0.5 * (alphaNext_[cl] + alphaNext_[ch]);
  const double fe = 0.5 * (fExplicit_[cl][d] + fExplicit_[ch][d]);
  const double sF = 0.5 * (source_[cl] + source_[ch]);
  return addSources(r, options_.gravity[d], fe, sF, d == 1 ? nozzleJetVelocity_ : 0.0, ud[f], aF, rho);
}

void GasSolver::rowRates(const std::array<std::vector<double>, 3>& u, int d, int j, int k, int i0, int i1,
                         double* out) const {
  // faceRate on faces i0 <= i < i1 of row (j, k) of axis d, whose stencils along x stay inside the
  // grid and whose neighbours along d exist: the same helpers in loops the compiler vectorises.
  constexpr int kChunk = 64;
  const Eigen::Vector3d hv = grid_.spacing;
  const double nu = scene_.gas.kinematic_viscosity, rho = scene_.gas.density;
  const auto n = grid_.shape;
  const auto& sd = ap_.shape[std::size_t(d)];
  const std::ptrdiff_t dStride[3] = {1, sd[0], std::ptrdiff_t(sd[0]) * sd[1]};
  const std::ptrdiff_t cellStride[3] = {1, n[0], std::ptrdiff_t(n[0]) * n[1]};
  const double* const ud = u[std::size_t(d)].data();
  const char* const kinds = kind_[std::size_t(d)].data();
  const int idx[3] = {0, j, k};
  const double gravity = options_.gravity[d], jet = d == 1 ? nozzleJetVelocity_ : 0.0;
  for (int c0 = i0; c0 < i1; c0 += kChunk) {
    const int m = std::min(kChunk, i1 - c0);
    const std::ptrdiff_t f0 = k * dStride[2] + j * dStride[1] + c0;
    alignas(64) double r[kChunk];
    for (int q = 0; q < m; ++q) r[q] = 0.0;
    for (int e = 0; e < 3; ++e) {
      alignas(64) double a[kChunk];
      if (e == d) {
        for (int q = 0; q < m; ++q) a[q] = ud[f0 + q];
      } else {
        const double* const ue = u[std::size_t(e)].data();
        const auto& se = ap_.shape[std::size_t(e)];
        const std::ptrdiff_t stride[3] = {1, se[0], std::ptrdiff_t(se[0]) * se[1]};
        const double* const p0 = ue + (k * stride[2] + j * stride[1] + c0);
        const double* const p1 = p0 + stride[e];
        const double* const p2 = p0 - stride[d];
        const double* const p3 = p2 + stride[e];
#pragma omp simd
        for (int q = 0; q < m; ++q) a[q] = 0.25 * (p0[q] + p1[q] + p2[q] + p3[q]);
      }
      // Inside along x (e = 0) the table gives shifts -2..2 and sign 1; along y and z the row's index
      // is fixed, so one table entry serves the whole row.
      const GhostPoint* g = &ghost_[std::size_t(d)][std::size_t(e)][std::size_t(e == 0 ? 2 : idx[e]) * 5];
      const double* v0 = ud + f0 + g[0].shift * dStride[e];
      const double* v1 = ud + f0 + g[1].shift * dStride[e];
      const double* v2 = ud + f0 + g[2].shift * dStride[e];
      const double* v3 = ud + f0 + g[3].shift * dStride[e];
      const double* v4 = ud + f0 + g[4].shift * dStride[e];
      const double s0 = g[0].sign, s1 = g[1].sign, s2 = g[2].sign, s3 = g[3].sign, s4 = g[4].sign;
      const double spacing = hv[e];
#pragma omp simd
      for (int q = 0; q < m; ++q)
        r[q] = addAdvectionDiffusion(r[q], a[q], s0 * v0[q], s1 * v1[q], s2 * v2[q], s3 * v3[q], s4 * v4[q], spacing, nu);
    }
    const std::ptrdiff_t ch0 = (std::ptrdiff_t(k) * n[1] + j) * n[0] + c0, cl0 = ch0 - cellStride[d];
    const double* const fx = fExplicit_.data()->data();
#pragma omp simd
    for (int q = 0; q < m; ++q) {
      const std::ptrdiff_t ch = ch0 + q, cl = cl0 + q;
      const double aF = 0.5 * (alphaNext_[std::size_t(cl)] + alphaNext_[std::size_t(ch)]);
      const double fe = 0.5 * (fx[3 * cl + d] + fx[3 * ch + d]);
      const double sF = 0.5 * (source_[std::size_t(cl)] + source_[std::size_t(ch)]);
      const double rate = addSources(r[q], gravity, fe, sF, jet, ud[f0 + q], aF, rho);
      out[f0 + q] = kinds[f0 + q] == Interior ? rate : 0.0;
    }
  }
}

void GasSolver::explicitRates(const std::array<std::vector<double>, 3>& u,
                              std::array<std::vector<double>, 3>& rate) const {
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    double* const out = rate[std::size_t(d)].data();
    const std::uint8_t* nearBaffle = nearBaffle_[std::size_t(d)].empty() ? nullptr : nearBaffle_[std::size_t(d)].data();
    const bool parallel = rate[std::size_t(d)].size() > kParallelFaces;
    // Faces with an x-stencil inside the grid and both cells along d: the vectorised row loop.
    const int i0 = 2, i1 = s[0] - 2;
#pragma omp parallel for collapse(2) schedule(static) if (parallel)
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j) {
        const std::size_t row = faceIndex(d, 0, j, k);
        // Faces on the grid boundary along d are never interior (inlet, outlet or wall).
        const bool boundaryRow = (d == 1 && (j == 0 || j == s[1] - 1)) || (d == 2 && (k == 0 || k == s[2] - 1));
        if (boundaryRow || i1 <= i0) {
          for (int i = 0; i < s[0]; ++i) out[row + std::size_t(i)] = boundaryRow ? 0.0 : faceRate(u, d, i, j, k);
          continue;
        }
        for (int i = 0; i < i0; ++i) out[row + std::size_t(i)] = faceRate(u, d, i, j, k);
        rowRates(u, d, j, k, i0, i1, out);
        for (int i = i1; i < s[0]; ++i) out[row + std::size_t(i)] = faceRate(u, d, i, j, k);
        if (nearBaffle)  // the plates' mirror images: the scalar path, for the few faces beside a plate
          for (int i = i0; i < i1; ++i)
            if (nearBaffle[row + std::size_t(i)]) out[row + std::size_t(i)] = faceRate(u, d, i, j, k);
      }
  }
}

}  // namespace rcfd::gas
