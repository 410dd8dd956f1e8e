// Eq. (3) smoothing, explicit conservative sub-steps (FieldSmoother.hpp).

#include "cfddem/coupling/FieldSmoother.hpp"

#include <algorithm>
#include <cmath>

namespace rcfd::coupling {

FieldSmoother::FieldSmoother(const VolumeMapping& mapping, const std::vector<char>& open0,
                             const std::vector<char>& open1, const std::vector<char>& open2, double length)
    : mapping_(mapping), length_(length) {
  const CartesianGrid& g = mapping.grid();
  const std::size_t cells = std::size_t(g.cellCount());
  invVolume_.assign(cells, 0.0);
  for (std::size_t c = 0; c < cells; ++c)
    if (mapping.usable()[c]) invVolume_[c] = 1.0 / mapping.openVolume(c);
  if (!(length_ > 0)) return;
  const Eigen::Vector3d h = g.spacing;
  // Stability (positivity) of the explicit step: D dtau sum_d 2 / h_d^2 <= 1 for a full cell; the
  // min(phi) conductance keeps the same bound in cut cells. D * total time = L^2.
  const double invH2 = 1 / (h.x() * h.x()) + 1 / (h.y() * h.y()) + 1 / (h.z() * h.z());
  subSteps_ = std::max(1, int(std::ceil(2.0 * length_ * length_ * invH2)));
  const double dDtau = length_ * length_ / subSteps_;
  const std::vector<char>* open[3] = {&open0, &open1, &open2};
  const auto n = g.shape;
  stride_ = {1, std::size_t(n[0]), std::size_t(n[0]) * std::size_t(n[1])};
  for (int d = 0; d < 3; ++d) {
    first_[std::size_t(d)] = stride_[std::size_t(d)];
    g_[std::size_t(d)].assign(cells, 0.0);
    const double area = g.cellVolume() / h[d];
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) {
          std::array<int, 3> hi{i, j, k};
          if (hi[std::size_t(d)] == 0) continue;
          std::array<int, 3> lo = hi;
          lo[std::size_t(d)] -= 1;
          // Face index of axis d: shape of the cells plus one along d.
          std::array<int, 3> fs = n;
          fs[std::size_t(d)] += 1;
          const std::size_t f = (std::size_t(k) * fs[1] + j) * fs[0] + i;
          if (!(*open[d])[f]) continue;
          const std::size_t a = std::size_t(g.flatIndex(lo[0], lo[1], lo[2]));
          const std::size_t b = std::size_t(g.flatIndex(hi[0], hi[1], hi[2]));
          if (!mapping.usable()[a] || !mapping.usable()[b]) continue;
          const double phi = std::min(mapping.openFraction()[a], mapping.openFraction()[b]);
          g_[std::size_t(d)][b] = dDtau * phi * area / h[d];
        }
  }
}

template <class T>
void FieldSmoother::smoothImpl(std::vector<T>& gamma) const {
  if (subSteps_ == 0) return;
  thread_local std::vector<T> change;
  const std::size_t n = gamma.size();
  change.resize(n);
  T* gm = gamma.data();
  T* ch = change.data();
  for (int s = 0; s < subSteps_; ++s) {
    std::fill(change.begin(), change.end(), T(gamma[0] * 0.0));
    for (int d = 0; d < 3; ++d) {
      // Face between c - stride and c: the flux into the low cell is what the high cell loses. The
      // faces of one axis never share a cell twice at the same offset, so the two updates are a
      // gather and a scatter of the same array in a fixed order (deterministic).
      const double* gd = g_[std::size_t(d)].data();
      const std::size_t st = stride_[std::size_t(d)];
      for (std::size_t c = first_[std::size_t(d)]; c < n; ++c) {
        if (gd[c] == 0.0) continue;
        const T flux = gd[c] * (gm[c] - gm[c - st]);
        ch[c - st] += flux;
        ch[c] -= flux;
      }
    }
    for (std::size_t c = 0; c < n; ++c) gm[c] += invVolume_[c] * ch[c];
  }
}

void FieldSmoother::smooth(std::vector<double>& gamma) const { smoothImpl(gamma); }
void FieldSmoother::smooth(std::vector<Eigen::Vector3d>& gamma) const { smoothImpl(gamma); }
void FieldSmoother::smooth(std::vector<Eigen::Vector4d>& gamma) const { smoothImpl(gamma); }

}  // namespace rcfd::coupling
