#pragma once
// Synthetic pseudo-periodic fields of the paper's size for the recurrence and database benchmarks:
// 73,647 cells (grid 49 x 167 x 9 = 73,647, the paper's cell count) sampled at 200 Hz. The bed "breathes"
// with a period near 0.3 s whose phase drifts slowly (so recurrences are strong but not exact), every
// cell has its own phase and amplitude, and a little deterministic noise keeps frames distinct.

#include <cmath>
#include <cstdint>

#include "fields/FieldDatabase.hpp"

namespace rcfd::bench {

inline CartesianGrid paperSizeGrid() {
  CartesianGrid g;
  g.origin = Eigen::Vector3d(-0.125, 0.0, 0.0);
  g.spacing = Eigen::Vector3d(0.005, 0.0036, 0.0222);
  g.shape = {49, 167, 9};  // 73,647 cells
  return g;
}

inline std::vector<float> paperSizeFluid(const CartesianGrid& g) {
  std::vector<float> f(std::size_t(g.cellCount()), 1.0f);
  for (std::size_t c = 0; c < f.size(); c += 13) f[c] = 0.5f;  // some cut cells at walls
  return f;
}

/// Uniform value in [-1, 1] from (cell, frame): splitmix64 of the pair.
inline double hashNoise(std::uint64_t c, std::uint64_t n) {
  std::uint64_t z = c * 0x9E3779B97F4A7C15ull + n * 0xBF58476D1CE4E5B9ull + 0x94D049BB133111EBull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-52 - 1.0;
}

/// Phase of the bed's oscillation at frame n (200 Hz): period 60 frames, drifting over 700 frames.
inline double bedPhase(int n) {
  return 2.0 * M_PI * n / 60.0 + 0.8 * std::sin(2.0 * M_PI * n / 700.0);
}

/// alpha_P of every cell at frame n.
inline void syntheticAlpha(const CartesianGrid& g, int n, float* out) {
  const double phase = bedPhase(n);
  const std::int64_t cells = g.cellCount();
  for (std::int64_t c = 0; c < cells; ++c) {
    const double k = 0.002 * double(c % 4096) + 0.3 * double(c / 4096);
    out[c] = float(0.3 + 0.2 * std::sin(phase + k) + 0.02 * hashNoise(std::uint64_t(c), std::uint64_t(n)));
  }
}

/// A full frame (alpha_P, u_P, u_G) at frame n.
inline void syntheticFrame(const CartesianGrid& g, int n, FieldFrame& f) {
  syntheticAlpha(g, n, f.alpha_p.data());
  const double phase = bedPhase(n);
  const std::int64_t cells = g.cellCount();
  for (std::int64_t c = 0; c < cells; ++c) {
    const double s = std::sin(phase + 0.001 * double(c));
    f.u_p[std::size_t(3 * c + 0)] = float(0.1 * s);
    f.u_p[std::size_t(3 * c + 1)] = float(1.2 * s + 0.05 * hashNoise(std::uint64_t(c), std::uint64_t(n) + 1));
    f.u_p[std::size_t(3 * c + 2)] = float(0.02 * s);
    f.u_g[std::size_t(3 * c + 0)] = float(0.5 * s);
    f.u_g[std::size_t(3 * c + 1)] = float(8.0 + 3.0 * s);
    f.u_g[std::size_t(3 * c + 2)] = 0.0f;
  }
}

}  // namespace rcfd::bench

namespace rcfd::bench {

/// The tracer and spray benchmarks' fields on the ProCell grid: a spout (|x - centre| < 20 mm, y < 0.3 m;
/// alpha_P 0.1, u_P 2.5 m/s up, u_G 12 m/s up) that sways left and right with period 0.5 s, a bed
/// (y < 0.15 m; alpha_P 0.55) sliding down and toward the spout, a dilute freeboard (alpha_P 0.01)
/// falling at 1 m/s, gas at 2 m/s outside the spout.
inline void swayingSpout(const CartesianGrid& grid, int, double t, FieldFrame& f) {
  const double centre = 0.02 * std::sin(2 * M_PI * t / 0.5);
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
    const double dx = p.x() - centre;
    const bool spout = std::abs(dx) < 0.02 && p.y() < 0.3;
    const bool bed = p.y() < 0.15;
    f.alpha_p[std::size_t(c)] = float(spout ? 0.1 : (bed ? 0.55 : 0.01));
    f.u_p[std::size_t(3 * c)] = float(spout ? 0.2 * dx / 0.02 : (bed ? -0.1 * std::copysign(1.0, dx) : 0.0));
    f.u_p[std::size_t(3 * c + 1)] = float(spout ? 2.5 : (bed ? -0.15 : -1.0));
    f.u_g[std::size_t(3 * c + 1)] = float(spout ? 12.0 : 2.0);
  }
}

}  // namespace rcfd::bench
