// GasSolver: the explicit rates of the predictor, advection + viscosity + explicit sources of Eq. (2)
// on the staggered faces (GasSolver.hpp; the scheme in docs/gas.md).
//
// The stencil of a face value reaches two faces either way along each axis. Where it leaves the grid
// the value comes from a ghost (mirror or copy, GhostPoint); which one depends only on the axis pair
// and the face's index along the stencil's axis, so buildStencils() tabulates it once and the rates
// loop does no index arithmetic beyond a lookup. In a thin slice (4 cells deep) every stencil along z
// leaves the grid, which made the per-point ghost search the largest cost of the gas phase.

#include <algorithm>

#include "cfddem/gas/FaceRates.hpp"
#include "cfddem/gas/GasSolver.hpp"
#include "core/Errors.hpp"

namespace rcfd::gas {
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

FaceRows faceRowsFor(Isa isa) {
  switch (isa) {
#if defined(RCFD_NATIVE_BUILD)
    case Isa::native: return isa_native::faceRows;
#else
    case Isa::avx2: return isa_avx2::faceRows;
    case Isa::avx512: return isa_avx512::faceRows;
#endif
    default: throw RunError(std::string("the gas's face rates have no ") + isaName(isa) + " variant in this build");
  }
}

void GasSolver::explicitRates(const std::array<std::vector<double>, 3>& u,
                              std::array<std::vector<double>, 3>& rate) const {
  FaceRowInputs rows;
  for (int d = 0; d < 3; ++d) {
    rows.u[d] = u[std::size_t(d)].data();
    rows.kinds[d] = kind_[std::size_t(d)].data();
    rows.faceShape[d] = ap_.shape[std::size_t(d)];
    rows.spacing[d] = grid_.spacing[d];
    rows.gravity[d] = options_.gravity[d];
    for (int e = 0; e < 3; ++e) rows.ghost[d][e] = ghost_[std::size_t(d)][std::size_t(e)].data();
  }
  rows.cells = grid_.shape;
  rows.interior = Interior;
  rows.nu = scene_.gas.kinematic_viscosity, rows.rho = scene_.gas.density;
  rows.jet = nozzleJetVelocity_;
  rows.alphaNext = alphaNext_.data();
  rows.fExplicit = fExplicit_.data()->data();
  rows.source = source_.data();
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
        faceRows_(rows, d, j, k, i0, i1, out);
        for (int i = i1; i < s[0]; ++i) out[row + std::size_t(i)] = faceRate(u, d, i, j, k);
        if (nearBaffle)  // the plates' mirror images: the scalar path, for the few faces beside a plate
          for (int i = i0; i < i1; ++i)
            if (nearBaffle[row + std::size_t(i)]) out[row + std::size_t(i)] = faceRate(u, d, i, j, k);
      }
  }
}

}  // namespace rcfd::gas
