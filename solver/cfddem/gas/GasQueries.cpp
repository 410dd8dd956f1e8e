// GasSolver queries for the coupling and the database job: interpolation at points, cell fields,
// boundary fluxes and the pressure drop (GasSolver.hpp).

#include <algorithm>
#include <cmath>

#include "cfddem/gas/GasSolver.hpp"

namespace rcfd::gas {
namespace {

/// Trilinear interpolation on the face lattice of axis d: value(f) gives the value of face f and
/// whether it counts. With `renormalise`, faces that do not count are left out and the weights of the
/// others rescaled; without, they count as zero.
template <class Value>
double interpolate(const std::array<int, 3>& shape, const CartesianGrid& g, int d, const Eigen::Vector3d& p,
                   bool renormalise, Value value) {
  int i0[3];
  double w1[3];
  for (int a = 0; a < 3; ++a) {
    // Face positions: o + i h along d, cell centres o + (i + 1/2) h across.
    const double t = (p[a] - g.origin[a]) / g.spacing[a] - (a == d ? 0.0 : 0.5);
    const int n = shape[std::size_t(a)];
    if (n == 1) {
      i0[a] = 0, w1[a] = 0.0;
      continue;
    }
    const double tc = std::clamp(t, 0.0, double(n - 1));
    i0[a] = std::min(int(std::floor(tc)), n - 2);
    w1[a] = tc - i0[a];
  }
  double sum = 0.0, wsum = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int o[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
    double w = 1.0;
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      w *= o[a] ? w1[a] : 1.0 - w1[a];
      idx[a] = std::min(i0[a] + o[a], shape[std::size_t(a)] - 1);
    }
    if (w == 0.0) continue;
    const std::size_t f = (std::size_t(idx[2]) * shape[1] + idx[1]) * shape[0] + idx[0];
    double v = 0.0;
    if (value(f, idx, v)) {
      sum += w * v;
      wsum += w;
    }
  }
  if (renormalise) return wsum > 0 ? sum / wsum : 0.0;
  return sum;
}

}  // namespace

Eigen::Vector3d GasSolver::velocityAt(const Eigen::Vector3d& p) const {
  Eigen::Vector3d u;
  for (int d = 0; d < 3; ++d) {
    const auto& ud = u_[std::size_t(d)];
    u[d] = interpolate(ap_.shape[std::size_t(d)], grid_, d, p, false, [&](std::size_t f, const int*, double& v) {
      v = ud[f];
      return true;
    });
  }
  return u;
}

void GasSolver::updatePressureGradient() {
  for (int d = 0; d < 3; ++d) {
    const double h = grid_.spacing[d];
    const auto& s = ap_.shape[std::size_t(d)];
    const auto& kinds = kind_[std::size_t(d)];
    auto& out = pressureGradient_[std::size_t(d)];
    out.assign(kinds.size(), 0.0);
#pragma omp parallel for collapse(2) schedule(static) if (out.size() > kParallelFaces)
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) {
          const std::size_t f = faceIndex(d, i, j, k);
          const char kind = kinds[f];
          if (kind != Interior && kind != Outlet) continue;
          int lo[3] = {i, j, k};
          lo[d] -= 1;
          const double pLo = p_[std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]))];
          if (kind == Interior) out[f] = (p_[std::size_t(grid_.flatIndex(i, j, k))] - pLo) / h;
          else out[f] = (0.0 - pLo) / (0.5 * h);  // the outlet's p = 0 half a cell away
        }
  }
}

Eigen::Vector3d GasSolver::pressureGradientAt(const Eigen::Vector3d& p) const {
  Eigen::Vector3d g;
  for (int d = 0; d < 3; ++d) {
    const auto& kinds = kind_[std::size_t(d)];
    const auto& gradient = pressureGradient_[std::size_t(d)];
    g[d] = interpolate(ap_.shape[std::size_t(d)], grid_, d, p, true, [&](std::size_t f, const int*, double& v) {
      const char kind = kinds[f];
      if (kind != Interior && kind != Outlet) return false;
      v = gradient[f];
      return true;
    });
  }
  return g;
}

std::vector<Eigen::Vector3d> GasSolver::cellVelocity() const {
  const auto n = grid_.shape;
  std::vector<Eigen::Vector3d> out(std::size_t(grid_.cellCount()), Eigen::Vector3d::Zero());
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const std::size_t c = std::size_t(grid_.flatIndex(i, j, k));
        if (!active_[c]) continue;
        out[c] = Eigen::Vector3d(0.5 * (u_[0][faceIndex(0, i, j, k)] + u_[0][faceIndex(0, i + 1, j, k)]),
                                 0.5 * (u_[1][faceIndex(1, i, j, k)] + u_[1][faceIndex(1, i, j + 1, k)]),
                                 0.5 * (u_[2][faceIndex(2, i, j, k)] + u_[2][faceIndex(2, i, j, k + 1)]));
      }
  return out;
}

double GasSolver::pressureDrop() const {
  double sum = 0.0, area = 0.0;
  const auto& s = ap_.shape[1];
  for (int k = 0; k < s[2]; ++k)
    for (int i = 0; i < s[0]; ++i) {
      const std::size_t f = faceIndex(1, i, 0, k);
      if (kind_[1][f] != Inlet) continue;
      sum += ap_.open[1][f] * p_[std::size_t(grid_.flatIndex(i, 0, k))];
      area += ap_.open[1][f];
    }
  return area > 0 ? sum / area : 0.0;  // minus the outlet pressure, 0 by the boundary condition
}

namespace {
double boundaryFlux(const GasSolver& g, const std::vector<char>& kinds, char which, int row) {
  const auto& s = g.apertures().shape[1];
  const auto& u = g.faceVelocity(1);
  const auto& open = g.apertures().open[1];
  const double area = g.grid().spacing.x() * g.grid().spacing.z();
  double sum = 0.0;
  for (int k = 0; k < s[2]; ++k)
    for (int i = 0; i < s[0]; ++i) {
      const std::size_t f = (std::size_t(k) * s[1] + row) * s[0] + i;
      if (kinds[f] != which) continue;
      const int cj = row == 0 ? 0 : row - 1;
      const double a = g.gasFractionOf(std::size_t(g.grid().flatIndex(i, cj, k)));
      sum += area * open[f] * a * u[f];
    }
  return sum;
}
}  // namespace

double GasSolver::inletFlow() const { return boundaryFlux(*this, kind_[1], GasSolver::Inlet, 0); }

double GasSolver::netOutflow() const {
  return boundaryFlux(*this, kind_[1], GasSolver::Outlet, ap_.shape[1][1] - 1) - inletFlow();
}

double GasSolver::nozzleFlow() const {
  double s = 0.0;
  for (double v : source_) s += v * grid_.cellVolume();
  return s;
}

double GasSolver::storageRate() const {
  double s = 0.0;
  for (std::size_t c = 0; c < phi_.size(); ++c)
    if (active_[c]) s += grid_.cellVolume() * phi_[c] * dAlphaDt_[c];
  return s;
}

}  // namespace rcfd::gas
