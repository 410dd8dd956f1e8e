#include "import/CartesianMapping.hpp"

#include <algorithm>
#include <deque>
#include <string>

#include "core/Errors.hpp"

namespace rcfd::openfoam {

CartesianMapping::CartesianMapping(const CartesianGrid& grid, std::vector<float> fluidFraction)
    : grid_(grid), fluid_(std::move(fluidFraction)) {
  const std::int64_t n = grid_.cellCount();
  if (std::int64_t(fluid_.size()) != n)
    throw RunError("CartesianMapping: " + std::to_string(fluid_.size()) + " open fractions for " + std::to_string(n) + " cells");
  neighbours_.assign(std::size_t(n), {-1, -1, -1, -1, -1, -1});
  for (int k = 0; k < grid_.shape[2]; ++k)
    for (int j = 0; j < grid_.shape[1]; ++j)
      for (int i = 0; i < grid_.shape[0]; ++i) {
        auto& nb = neighbours_[std::size_t(grid_.flatIndex(i, j, k))];
        const int ijk[3] = {i, j, k};
        for (int d = 0; d < 3; ++d)
          for (int s = 0; s < 2; ++s) {
            int c[3] = {ijk[0], ijk[1], ijk[2]};
            c[d] += s == 0 ? -1 : 1;
            if (c[d] >= 0 && c[d] < grid_.shape[d]) nb[std::size_t(2 * d + s)] = grid_.flatIndex(c[0], c[1], c[2]);
          }
      }
  // Nearest open cell of every cell: breadth-first from all open cells at once, in face steps.
  nearestOpen_.assign(std::size_t(n), -1);
  std::deque<std::int64_t> queue;
  for (std::int64_t c = 0; c < n; ++c)
    if (fluid_[std::size_t(c)] > 0.0f) {
      nearestOpen_[std::size_t(c)] = c;
      queue.push_back(c);
    }
  if (queue.empty()) throw InputError("scene", "/apparatus", "the grid has no open cell to map the OpenFOAM case onto");
  while (!queue.empty()) {
    const std::int64_t c = queue.front();
    queue.pop_front();
    for (std::int64_t nb : neighbours_[std::size_t(c)])
      if (nb >= 0 && nearestOpen_[std::size_t(nb)] < 0) {
        nearestOpen_[std::size_t(nb)] = nearestOpen_[std::size_t(c)];
        queue.push_back(nb);
      }
  }
  beginFrame();
}

std::int64_t CartesianMapping::receivingCell(const Eigen::Vector3d& p, bool* redirected, bool* outside) const {
  const Eigen::Vector3d upper = grid_.upperCorner();
  const bool out = (p.array() < grid_.origin.array()).any() || (p.array() > upper.array()).any();
  const std::int64_t c = grid_.flatIndexOf(p);
  const std::int64_t r = nearestOpen_[std::size_t(c)];
  if (redirected) *redirected = out || r != c;
  if (outside) *outside = out;
  return r;
}

void CartesianMapping::beginFrame() {
  const std::size_t n = std::size_t(grid_.cellCount());
  particleVolume_.assign(n, 0.0);
  gasVolume_.assign(n, 0.0);
  particleMomentum_.assign(3 * n, 0.0);
  gasMomentum_.assign(3 * n, 0.0);
  redirected_ = outside_ = 0;
  received_ = 0.0;
  received_particles_.clear();
}

void CartesianMapping::addParticles(const Eigen::Vector3d& at, double volume, const Eigen::Vector3d& velocity) {
  bool redirected = false, outside = false;
  const std::size_t c = std::size_t(receivingCell(at, &redirected, &outside));
  redirected_ += redirected;
  outside_ += outside;
  particleVolume_[c] += volume;
  received_ += volume;
  for (int d = 0; d < 3; ++d) particleMomentum_[3 * c + std::size_t(d)] += volume * velocity[d];
  if (spread_) received_particles_.push_back({at, velocity, volume, c});
}

void CartesianMapping::addGas(const Eigen::Vector3d& at, double volume, const Eigen::Vector3d& velocity) {
  bool redirected = false, outside = false;
  const std::size_t c = std::size_t(receivingCell(at, &redirected, &outside));
  redirected_ += redirected;
  outside_ += outside;
  gasVolume_[c] += volume;
  for (int d = 0; d < 3; ++d) gasMomentum_[3 * c + std::size_t(d)] += volume * velocity[d];
}

void CartesianMapping::redistributeOverfull(MappingCounts& counts) {
  const std::size_t n = particleVolume_.size();
  const double cellVolume = grid_.cellVolume();
  const auto capacity = [&](std::size_t c) { return cellVolume * double(fluid_[c]); };
  // A pass moves each over-full cell's excess to its open face neighbours: in proportion to their free
  // room where that holds it, else in proportion to their open volume (they pass it on in later passes).
  constexpr int kMaxPasses = 100000;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    bool any = false;
    for (std::size_t c = 0; c < n; ++c) {
      const double excess = particleVolume_[c] - capacity(c);
      if (!(excess > 0.0) || fluid_[c] <= 0.0f) continue;
      double free = 0.0, open = 0.0;
      for (std::int64_t nb : neighbours_[c]) {
        if (nb < 0 || fluid_[std::size_t(nb)] <= 0.0f) continue;
        free += std::max(0.0, capacity(std::size_t(nb)) - particleVolume_[std::size_t(nb)]);
        open += capacity(std::size_t(nb));
      }
      if (open <= 0.0) continue;  // an isolated open cell: nothing can take its excess
      if (pass == 0) ++counts.overfullCells;
      any = true;
      const bool fits = free >= excess;
      const double velocityShare[3] = {particleMomentum_[3 * c] / particleVolume_[c],
                                       particleMomentum_[3 * c + 1] / particleVolume_[c],
                                       particleMomentum_[3 * c + 2] / particleVolume_[c]};
      for (std::int64_t nb : neighbours_[c]) {
        if (nb < 0 || fluid_[std::size_t(nb)] <= 0.0f) continue;
        const std::size_t m = std::size_t(nb);
        const double share = fits ? std::max(0.0, capacity(m) - particleVolume_[m]) / free : capacity(m) / open;
        const double moved = excess * share;
        particleVolume_[m] += moved;
        particleVolume_[c] -= moved;
        for (int d = 0; d < 3; ++d) {
          particleMomentum_[3 * m + std::size_t(d)] += moved * velocityShare[d];
          particleMomentum_[3 * c + std::size_t(d)] -= moved * velocityShare[d];
        }
      }
      if (particleVolume_[c] > capacity(c)) particleVolume_[c] = capacity(c);  // the last rounding bit
    }
    if (!any) return;
  }
  throw InputError("OpenFOAM case", "particle volume",
                   "more particle volume than the scene's open volume around it can hold (alpha_P > 1 remains after "
                   "spreading it): does the scene's apparatus match the OpenFOAM geometry?");
}

FieldFrame CartesianMapping::finishFrame(MappingCounts& counts) {
  counts = MappingCounts{};
  counts.redirected = redirected_;
  counts.outsideGrid = outside_;
  counts.particleVolume = received_;
  redistributeOverfull(counts);
  const std::size_t n = particleVolume_.size();
  const double cellVolume = grid_.cellVolume();
  FieldFrame f;
  f.alpha_p.assign(n, 0.0f);
  f.u_p.assign(3 * n, 0.0f);
  f.u_g.assign(3 * n, 0.0f);
  std::vector<char> filled(n, 0);
  for (std::size_t c = 0; c < n; ++c) {
    if (fluid_[c] <= 0.0f) continue;
    const double v = particleVolume_[c];
    if (v > 0.0) {
      f.alpha_p[c] = float(std::min(1.0, v / (cellVolume * double(fluid_[c]))));
      for (int d = 0; d < 3; ++d) f.u_p[3 * c + std::size_t(d)] = float(particleMomentum_[3 * c + std::size_t(d)] / v);
    }
    if (gasVolume_[c] > 0.0) {
      filled[c] = 1;
      for (int d = 0; d < 3; ++d) f.u_g[3 * c + std::size_t(d)] = float(gasMomentum_[3 * c + std::size_t(d)] / gasVolume_[c]);
    }
    counts.mappedParticleVolume += double(f.alpha_p[c]) * cellVolume * double(fluid_[c]);
  }
  // Open cells no mesh cell centre fell into: the mean of their filled face neighbours, one wave at a time.
  for (;;) {
    std::vector<std::size_t> wave;
    for (std::size_t c = 0; c < n; ++c) {
      if (filled[c] || fluid_[c] <= 0.0f) continue;
      for (std::int64_t nb : neighbours_[c])
        if (nb >= 0 && filled[std::size_t(nb)] == 1) {
          wave.push_back(c);
          break;
        }
    }
    if (wave.empty()) break;
    for (std::size_t c : wave) {
      double sum[3] = {0, 0, 0};
      int k = 0;
      for (std::int64_t nb : neighbours_[c])
        if (nb >= 0 && filled[std::size_t(nb)] == 1) {
          for (int d = 0; d < 3; ++d) sum[d] += f.u_g[3 * std::size_t(nb) + std::size_t(d)];
          ++k;
        }
      for (int d = 0; d < 3; ++d) f.u_g[3 * c + std::size_t(d)] = float(sum[d] / k);
    }
    for (std::size_t c : wave) filled[c] = 1;  // a source from the next wave on
    counts.gasFilledCells += std::int64_t(wave.size());
  }
  if (spread_) addVelocitySpread(f);
  return f;
}

Eigen::Vector3d CartesianMapping::interpolatedMean(const FieldFrame& f, const Eigen::Vector3d& p,
                                                   std::size_t cell) const {
  int lo[3];
  double fraction[3];
  for (int d = 0; d < 3; ++d) {
    const int n = grid_.shape[std::size_t(d)];
    const double t = std::clamp((p[d] - grid_.origin[d]) / grid_.spacing[d] - 0.5, 0.0, double(n - 1));
    lo[d] = std::min(int(t), std::max(0, n - 2));
    fraction[d] = n > 1 ? t - double(lo[d]) : 0.0;
  }
  // Weighted by alpha_P as well (the mass-weighted velocity of the tracers, docs/calibration.md): a
  // corner without particles has no velocity of its own to give.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weights = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    int ijk[3];
    double w = 1.0;
    for (int d = 0; d < 3; ++d) {
      const bool upper = (corner >> d) & 1;
      w *= upper ? fraction[d] : 1.0 - fraction[d];
      ijk[d] = lo[d] + (upper && grid_.shape[std::size_t(d)] > 1 ? 1 : 0);
    }
    if (!(w > 0.0)) continue;
    const std::size_t c = std::size_t(grid_.flatIndex(ijk[0], ijk[1], ijk[2]));
    const double a = f.alpha_p[c];
    if (!(a > 0.0) || fluid_[c] <= 0.0f) continue;
    sum += w * a * Eigen::Vector3d(f.u_p[3 * c], f.u_p[3 * c + 1], f.u_p[3 * c + 2]);
    weights += w * a;
  }
  if (weights > 0.0) return sum / weights;
  return {f.u_p[3 * cell], f.u_p[3 * cell + 1], f.u_p[3 * cell + 2]};
}

void CartesianMapping::addVelocitySpread(FieldFrame& f) const {
  // As the database job's (coupling::VolumeMapping::velocitySpread()): the share of the particle volume
  // moving up, the mean velocities of the up- and down-moving parts, and the variance per component
  // about the mean a tracer at the particle's position moves with (the mean's own variation across a
  // cell is not a fluctuation).
  const std::size_t n = f.alpha_p.size();
  std::vector<double> volume(n, 0.0), upVolume(n, 0.0);
  std::vector<Eigen::Vector3d> up(n, Eigen::Vector3d::Zero()), down(n, Eigen::Vector3d::Zero()),
      variance(n, Eigen::Vector3d::Zero());
  for (const Received& r : received_particles_) {
    const bool rising = r.velocity.y() > 0.0;
    volume[r.cell] += r.volume;
    (rising ? up : down)[r.cell] += r.volume * r.velocity;
    if (rising) upVolume[r.cell] += r.volume;
    variance[r.cell] += r.volume * (r.velocity - interpolatedMean(f, r.at, r.cell)).cwiseAbs2();
  }
  f.up_fraction.assign(n, 0.0f);
  f.u_p_up.assign(3 * n, 0.0f);
  f.u_p_down.assign(3 * n, 0.0f);
  f.u_p_variance.assign(3 * n, 0.0f);
  for (std::size_t c = 0; c < n; ++c) {
    if (!(volume[c] > 0.0)) continue;
    const double downVolume = volume[c] - upVolume[c];
    const Eigen::Vector3d mean(f.u_p[3 * c], f.u_p[3 * c + 1], f.u_p[3 * c + 2]);
    const Eigen::Vector3d u = upVolume[c] > 0.0 ? Eigen::Vector3d(up[c] / upVolume[c]) : mean;
    const Eigen::Vector3d v = downVolume > 0.0 ? Eigen::Vector3d(down[c] / downVolume) : mean;
    f.up_fraction[c] = float(std::clamp(upVolume[c] / volume[c], 0.0, 1.0));
    for (int d = 0; d < 3; ++d) {
      f.u_p_up[3 * c + std::size_t(d)] = float(u[d]);
      f.u_p_down[3 * c + std::size_t(d)] = float(v[d]);
      f.u_p_variance[3 * c + std::size_t(d)] = float(variance[c][d] / volume[c]);
    }
  }
}

}  // namespace rcfd::openfoam
