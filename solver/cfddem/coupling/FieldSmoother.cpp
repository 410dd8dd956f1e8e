// Eq. (3) smoothing, explicit conservative sub-steps (FieldSmoother.hpp).

#include "cfddem/coupling/FieldSmoother.hpp"

#include <algorithm>
#include <cmath>

namespace rcfd::coupling {


FieldSmoother::FieldSmoother(const VolumeMapping& mapping, const std::vector<char>& open0,
                             const std::vector<char>& open1, const std::vector<char>& open2, double length)
    : mapping_(mapping), length_(length) {
  const CartesianGrid& g = mapping.grid();
  cells_ = std::size_t(g.cellCount());
  const auto n = g.shape;
  stride_ = {1, std::size_t(n[0]), std::size_t(n[0]) * std::size_t(n[1])};
  pad_ = stride_[2];
  const std::size_t padded = cells_ + 2 * pad_;
  invVolume_.assign(padded, 0.0);
  for (std::size_t c = 0; c < cells_; ++c)
    if (mapping.usable()[c]) invVolume_[pad_ + c] = 1.0 / mapping.openVolume(c);
  if (!(length_ > 0)) return;
  const Eigen::Vector3d h = g.spacing;
  // Stability (positivity) of the explicit step: D dtau sum_d 2 / h_d^2 <= 1 for a full cell; the
  // min(phi) conductance keeps the same bound in cut cells. D * total time = L^2.
  const double invH2 = 1 / (h.x() * h.x()) + 1 / (h.y() * h.y()) + 1 / (h.z() * h.z());
  subSteps_ = std::max(1, int(std::ceil(2.0 * length_ * length_ * invH2)));
  const double dDtau = length_ * length_ / subSteps_;
  const std::vector<char>* open[3] = {&open0, &open1, &open2};
  for (int d = 0; d < 3; ++d) {
    g_[std::size_t(d)].assign(padded, 0.0);
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
          g_[std::size_t(d)][pad_ + b] = dDtau * phi * area / h[d];
        }
  }
}

namespace {

/// The sub-steps of K component planes (padded layout, see FieldSmoother::pad_), in place; `spare`
/// holds K more planes. The components share the conductance loads of one sweep.
template <int K>
void gatherSweeps(std::array<double*, K> field, std::array<double*, K> spare, const std::array<const double*, 3>& g,
                  const double* inv, std::size_t sy, std::size_t sz, std::size_t lo, std::size_t hi, int subSteps,
                  bool parallel) {
  const double* gx = g[0];
  const double* gy = g[1];
  const double* gz = g[2];
  // Gather form: each cell adds the fluxes through its six faces, each flux written with the same
  // operands in the same order as in the neighbour that loses it (the two see one value with opposite
  // signs), so the sum V phi gamma is conserved to round-off. A cell writes only itself: any split
  // over threads gives the same bits. Reads into the padding meet zero conductances.
#pragma omp parallel if (parallel)
  {
    std::array<double*, K> a = field, b = spare;
    for (int s = 0; s < subSteps; ++s) {
#pragma omp for simd schedule(simd : static)
      for (std::size_t c = lo; c < hi; ++c) {
        const double wxl = gx[c], wxh = gx[c + 1], wyl = gy[c], wyh = gy[c + sy], wzl = gz[c], wzh = gz[c + sz];
        for (int q = 0; q < K; ++q) {
          const double* x = a[std::size_t(q)];
          const double v = x[c];
          const double flux = wxh * (x[c + 1] - v) - wxl * (v - x[c - 1]) + wyh * (x[c + sy] - v) -
                              wyl * (v - x[c - sy]) + wzh * (x[c + sz] - v) - wzl * (v - x[c - sz]);
          b[std::size_t(q)][c] = v + inv[c] * flux;
        }
      }  // (the loop's barrier: every cell of this sub-step is written before the next reads it)
      std::swap(a, b);
    }
    if (a[0] != field[0]) {
#pragma omp for schedule(static)
      for (std::size_t c = lo; c < hi; ++c)
        for (int q = 0; q < K; ++q) field[std::size_t(q)][c] = a[std::size_t(q)][c];
    }
  }
}

}  // namespace

template <class T>
void FieldSmoother::smoothImpl(std::vector<T>& gamma) const {
  if (subSteps_ == 0) return;
  constexpr int K = int(sizeof(T) / sizeof(double));
  // Components to planes of their own: the sweep then reads contiguous doubles (vectorised).
  thread_local std::vector<double> planes;
  const std::size_t padded = cells_ + 2 * pad_;
  // K planes and K spares, their padding zeroed on every call: the scratch is shared by every
  // smoother of this thread, and another grid's interior may have covered this one's padding.
  planes.resize(2 * K * padded);
  for (int q = 0; q < 2 * K; ++q) {
    double* plane = planes.data() + std::size_t(q) * padded;
    std::fill(plane, plane + pad_, 0.0);
    std::fill(plane + pad_ + cells_, plane + padded, 0.0);
  }
  std::array<double*, K> field, spare;
  for (int q = 0; q < K; ++q) {
    field[std::size_t(q)] = planes.data() + std::size_t(q) * padded;
    spare[std::size_t(q)] = planes.data() + std::size_t(K + q) * padded;
  }
  const bool parallel = cells_ >= std::size_t(kParallelCells);
  const long cells = long(cells_);
  const double* src = reinterpret_cast<const double*>(gamma.data());
#pragma omp parallel for schedule(static) if (parallel)
  for (long c = 0; c < cells; ++c)
    for (int q = 0; q < K; ++q) field[std::size_t(q)][pad_ + std::size_t(c)] = src[std::size_t(c) * K + q];
  gatherSweeps<K>(field, spare, {g_[0].data(), g_[1].data(), g_[2].data()}, invVolume_.data(), stride_[1],
                  stride_[2], pad_, pad_ + cells_, subSteps_, parallel);
  double* dst = reinterpret_cast<double*>(gamma.data());
#pragma omp parallel for schedule(static) if (parallel)
  for (long c = 0; c < cells; ++c)
    for (int q = 0; q < K; ++q) dst[std::size_t(c) * K + q] = field[std::size_t(q)][pad_ + std::size_t(c)];
}

void FieldSmoother::smooth(std::vector<double>& gamma) const { smoothImpl(gamma); }
void FieldSmoother::smooth(std::vector<Eigen::Vector3d>& gamma) const { smoothImpl(gamma); }
void FieldSmoother::smooth(std::vector<Eigen::Vector4d>& gamma) const { smoothImpl(gamma); }

}  // namespace rcfd::coupling
