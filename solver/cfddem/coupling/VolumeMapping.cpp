// Cloud-in-cell particle volume mapping on open cells and its over-packing treatment (VolumeMapping.hpp).

#include "cfddem/coupling/VolumeMapping.hpp"

#include <algorithm>
#include <exception>
#include <cmath>
#include <omp.h>
#include <sstream>

#include "core/Errors.hpp"

namespace rcfd::coupling {

/// A cell counts as over-packed above maxFraction (1 + this): the Jacobi sweeps converge geometrically.
constexpr double kRedistributionTolerance = 1e-9;

VolumeMapping::VolumeMapping(const CartesianGrid& grid, std::vector<double> openFraction, std::vector<char> usable,
                             BaffleFaces baffles)
    : grid_(grid), phi_(std::move(openFraction)), usable_(std::move(usable)), baffles_(std::move(baffles)) {
  if (phi_.size() != std::size_t(grid_.cellCount()) || usable_.size() != phi_.size())
    throw RunError("volume mapping: open fractions do not match the grid");
  for (std::size_t c = 0; c < phi_.size(); ++c)
    if (!(phi_[c] > 0)) usable_[c] = 0;
}

KernelWeights VolumeMapping::weights(const Eigen::Vector3d& x) const {
  KernelWeights out;
  int i0[3];
  double w1[3];
  for (int a = 0; a < 3; ++a) {
    // Cell centres sit at o + (i + 1/2) h; beyond the outermost centres the weight stays on them.
    const int n = grid_.shape[std::size_t(a)];
    const double t = std::clamp((x[a] - grid_.origin[a]) / grid_.spacing[a] - 0.5, 0.0, double(n - 1));
    i0[a] = n == 1 ? 0 : std::min(int(std::floor(t)), n - 2);
    w1[a] = n == 1 ? 0.0 : t - i0[a];
  }
  const bool cut = !baffles_.empty();
  // A parcel between a plate and the face the plate is snapped to counts from the cell across that
  // face: the side of the plate it is on (BaffleFaces::homeCell).
  const std::array<int, 3> home = cut ? baffles_.homeCell(grid_, x) : std::array<int, 3>{};
  double sum = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int o[3] = {c & 1, (c >> 1) & 1, (c >> 2) & 1};
    double w = 1.0;
    for (int a = 0; a < 3; ++a) w *= o[a] ? w1[a] : 1.0 - w1[a];
    if (w == 0.0) continue;
    const std::int64_t cell = grid_.flatIndex(i0[0] + o[0], i0[1] + o[1], i0[2] + o[2]);
    if (!usable_[std::size_t(cell)]) continue;
    if (cut && !reachable(home, {i0[0] + o[0], i0[1] + o[1], i0[2] + o[2]})) continue;  // behind a plate
    w *= phi_[std::size_t(cell)];  // a cut cell takes its open share only
    out.cell[std::size_t(out.count)] = std::int32_t(cell);
    out.w[std::size_t(out.count)] = w;
    ++out.count;
    sum += w;
  }
  if (out.count > 0) {
    const double inv = 1.0 / sum;
    double total = 0.0;
    for (int k = 0; k < out.count; ++k) total += (out.w[std::size_t(k)] *= inv);
    out.w[0] += 1.0 - total;  // the weights sum to one to the last bit: volume is conserved exactly
    return out;
  }
  // All eight centres closed (a parcel in a narrow gap between walls): its nearest usable cell.
  const auto own = grid_.cellOf(x);
  double best = 1e300;
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const int i = own[0] + di, j = own[1] + dj, k = own[2] + dk;
        if (i < 0 || j < 0 || k < 0 || i >= grid_.shape[0] || j >= grid_.shape[1] || k >= grid_.shape[2]) continue;
        const std::int64_t cell = grid_.flatIndex(i, j, k);
        if (!usable_[std::size_t(cell)]) continue;
        const double d2 = (grid_.cellCenter(i, j, k) - x).squaredNorm();
        if (d2 < best) best = d2, out.cell[0] = std::int32_t(cell);
      }
  if (best == 1e300) {
    std::ostringstream s;
    s << "volume mapping: no open gas cell near the parcel at (" << x.x() << ", " << x.y() << ", " << x.z()
      << ") m";
    throw RunError(s.str());
  }
  out.w[0] = 1.0;
  out.count = 1;
  return out;
}

bool VolumeMapping::reachable(const std::array<int, 3>& from, const std::array<int, 3>& to) const {
  // Depth-first over the axes along which from and to still differ (at most 3! paths of 3 steps).
  for (int a = 0; a < 3; ++a) {
    if (from[std::size_t(a)] == to[std::size_t(a)]) continue;
    // The face between from and its neighbour along a carries the larger cell index.
    std::array<int, 3> face = from;
    face[std::size_t(a)] = std::max(from[std::size_t(a)], to[std::size_t(a)]);
    if (baffles_.closes(a, face[0], face[1], face[2])) continue;
    std::array<int, 3> next = from;
    next[std::size_t(a)] = to[std::size_t(a)];
    if (reachable(next, to)) return true;
  }
  return from == to;
}

void VolumeMapping::weightsOf(const DemParticles& p, std::vector<KernelWeights>& out) const {
  out.resize(p.size());
  const long n = long(p.size());
  // An exception must not leave an OpenMP region (std::terminate): the first parcel's failure (in
  // parcel order, whatever the threads) is thrown after it.
  long failed = n;
  std::exception_ptr failure;
#pragma omp parallel for schedule(static) if (n >= 4096)
  for (long i = 0; i < n; ++i) {
    try {
      out[std::size_t(i)] = weights(p.x[std::size_t(i)]);
    } catch (...) {
#pragma omp critical(rcfd_volume_mapping_failure)
      if (i < failed) failed = i, failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}

void VolumeMapping::scatterVolume(const DemParticles& p, const std::vector<KernelWeights>& w,
                                  std::vector<double>& volume) const {
  volume.assign(phi_.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double v = parcelVolume(p, i);
    for (int k = 0; k < w[i].count; ++k) volume[std::size_t(w[i].cell[std::size_t(k)])] += w[i].w[std::size_t(k)] * v;
  }
}

void VolumeMapping::contributionsOf(const std::vector<KernelWeights>& w, CellContributions& out) const {
  const std::size_t cells = phi_.size();
  const long n = long(w.size());
  const int chunks = n >= kParallelParcels ? omp_get_max_threads() : 1;
  // counts[k * cells + c]: entries of chunk k in cell c, then where chunk k writes its next one there.
  std::vector<std::int32_t> counts(std::size_t(chunks) * cells, 0);
  out.start.resize(cells + 1);
#pragma omp parallel num_threads(chunks) if (chunks > 1)
  {
    // The team may be smaller than asked (inside another parallel region): its own size splits the work.
    const int team = omp_get_num_threads(), k = omp_get_thread_num();
    const long i0 = n * k / team, i1 = n * (k + 1) / team;
    std::int32_t* mine = counts.data() + std::size_t(k) * cells;
    for (long i = i0; i < i1; ++i)
      for (int q = 0; q < w[std::size_t(i)].count; ++q) ++mine[w[std::size_t(i)].cell[std::size_t(q)]];
#pragma omp barrier
#pragma omp single
    {
      std::int32_t running = 0;
      for (std::size_t c = 0; c < cells; ++c) {
        out.start[c] = running;
        for (int j = 0; j < team; ++j) {
          const std::int32_t here = counts[std::size_t(j) * cells + c];
          counts[std::size_t(j) * cells + c] = running;
          running += here;
        }
      }
      out.start[cells] = running;
      out.parcel.resize(std::size_t(running));
      out.weight.resize(std::size_t(running));
    }  // (single's barrier: every chunk's offsets are set before any chunk writes)
    for (long i = i0; i < i1; ++i)
      for (int q = 0; q < w[std::size_t(i)].count; ++q) {
        const std::int32_t e = mine[w[std::size_t(i)].cell[std::size_t(q)]]++;
        out.parcel[std::size_t(e)] = std::int32_t(i);
        out.weight[std::size_t(e)] = w[std::size_t(i)].w[std::size_t(q)];
      }
  }
}

void VolumeMapping::gatherVolume(const DemParticles& p, const CellContributions& c, std::vector<double>& volume) const {
  const long cells = long(phi_.size());
  volume.resize(std::size_t(cells));
#pragma omp parallel for schedule(static) if (cells >= kParallelCells)
  for (long cell = 0; cell < cells; ++cell) {
    double v = 0.0;
    for (std::int32_t e = c.start[std::size_t(cell)]; e < c.start[std::size_t(cell) + 1]; ++e)
      v += c.weight[std::size_t(e)] * parcelVolume(p, std::size_t(c.parcel[std::size_t(e)]));
    volume[std::size_t(cell)] = v;
  }
}

std::vector<double> VolumeMapping::fractionOf(const std::vector<double>& volume) const {
  std::vector<double> a(volume.size(), 0.0);
  for (std::size_t c = 0; c < a.size(); ++c)
    if (usable_[c]) a[c] = volume[c] / openVolume(c);
  return a;
}

long VolumeMapping::redistributeExcess(std::vector<double>& volume, double maxFraction, int maxSweeps) const {
  const auto n = grid_.shape;
  std::vector<std::size_t> over;
  std::vector<char> gave(volume.size(), 0);
  std::vector<double> moved;
  for (int sweep = 0; sweep < maxSweeps; ++sweep) {
    over.clear();
    for (std::size_t c = 0; c < volume.size(); ++c)
      if (usable_[c] && volume[c] > maxFraction * openVolume(c) * (1.0 + kRedistributionTolerance)) over.push_back(c);
    if (over.empty()) break;
    // Jacobi sweep: every over-full cell hands its excess to its usable face neighbours in proportion
    // to their open volume; a neighbour pushed above the limit passes it on in the next sweep.
    moved.assign(volume.size(), 0.0);
    for (std::size_t c : over) {
      const double excess = volume[c] - maxFraction * openVolume(c);
      const auto ijk = grid_.cellIjk(std::int64_t(c));
      std::size_t nb[6];
      int count = 0;
      double capacity = 0.0;
      for (int d = 0; d < 3; ++d)
        for (int s = -1; s <= 1; s += 2) {
          auto q = ijk;
          q[std::size_t(d)] += s;
          if (q[std::size_t(d)] < 0 || q[std::size_t(d)] >= n[std::size_t(d)]) continue;
          const std::size_t m = std::size_t(grid_.flatIndex(q[0], q[1], q[2]));
          if (!usable_[m]) continue;
          auto face = ijk;
          face[std::size_t(d)] = std::max(ijk[std::size_t(d)], q[std::size_t(d)]);
          if (baffles_.closes(d, face[0], face[1], face[2])) continue;  // nothing crosses a plate
          nb[count++] = m;
          capacity += openVolume(m);
        }
      if (count == 0) continue;  // an isolated cell keeps its volume (checked by the caller's alpha_G)
      gave[c] = 1;
      moved[c] -= excess;
      for (int k = 0; k < count; ++k) moved[nb[k]] += excess * openVolume(nb[k]) / capacity;
    }
    for (std::size_t c = 0; c < volume.size(); ++c) volume[c] += moved[c];
  }
  return long(std::count(gave.begin(), gave.end(), char(1)));
}

std::vector<Eigen::Vector3d> VolumeMapping::meanVelocity(const DemParticles& p,
                                                         const std::vector<KernelWeights>& w) const {
  std::vector<Eigen::Vector3d> mom(phi_.size(), Eigen::Vector3d::Zero());
  std::vector<double> vol(phi_.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double v = parcelVolume(p, i);
    for (int k = 0; k < w[i].count; ++k) {
      const std::size_t c = std::size_t(w[i].cell[std::size_t(k)]);
      vol[c] += w[i].w[std::size_t(k)] * v;
      mom[c] += (w[i].w[std::size_t(k)] * v) * p.v[i];
    }
  }
  for (std::size_t c = 0; c < mom.size(); ++c) mom[c] = vol[c] > 0 ? Eigen::Vector3d(mom[c] / vol[c]) : Eigen::Vector3d::Zero();
  return mom;
}

VolumeMapping::VelocitySpread VolumeMapping::velocitySpread(const DemParticles& p,
                                                           const std::vector<KernelWeights>& w) const {
  const std::size_t cells = phi_.size();
  VelocitySpread s;
  s.mean = meanVelocity(p, w);
  s.up.assign(cells, Eigen::Vector3d::Zero());
  s.down.assign(cells, Eigen::Vector3d::Zero());
  s.variance.assign(cells, Eigen::Vector3d::Zero());
  s.upFraction.assign(cells, 0.0);
  std::vector<double> volume(cells, 0.0), upVolume(cells, 0.0), downVolume(cells, 0.0);
  // Serial scatter in index order, as meanVelocity(): deterministic sums. The variance is taken about
  // the mean interpolated to each parcel with its own weights, not about the cell's mean: tracers move
  // with u_P^rec interpolated to their position, so the part of the spread that is the mean's variation
  // across the kernel (shear across a wall layer or a spout's edge) they already have, and counting it
  // again as a random fluctuation would spread them across that edge. What is left is what the
  // interpolated mean loses (law of total variance at the parcels' positions).
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double v = parcelVolume(p, i);
    const bool up = p.v[i].y() > 0.0;
    const Eigen::Vector3d meanHere = interpolate(s.mean, w[i]);
    for (int k = 0; k < w[i].count; ++k) {
      const std::size_t c = std::size_t(w[i].cell[std::size_t(k)]);
      const double wv = w[i].w[std::size_t(k)] * v;
      volume[c] += wv;
      (up ? s.up[c] : s.down[c]) += wv * p.v[i];
      (up ? upVolume[c] : downVolume[c]) += wv;
      s.variance[c] += wv * (p.v[i] - meanHere).cwiseAbs2();
    }
  }
  for (std::size_t c = 0; c < cells; ++c) {
    if (!(volume[c] > 0.0)) {
      s.up[c] = s.down[c] = s.variance[c] = Eigen::Vector3d::Zero();
      continue;
    }
    s.upFraction[c] = std::clamp(upVolume[c] / volume[c], 0.0, 1.0);
    s.up[c] = upVolume[c] > 0.0 ? Eigen::Vector3d(s.up[c] / upVolume[c]) : s.mean[c];
    s.down[c] = downVolume[c] > 0.0 ? Eigen::Vector3d(s.down[c] / downVolume[c]) : s.mean[c];
    s.variance[c] /= volume[c];
  }
  return s;
}

}  // namespace rcfd::coupling
