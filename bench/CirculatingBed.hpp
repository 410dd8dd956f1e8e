#pragma once
// A circulating spouted bed for the tracer and spray benchmarks. Not the swaying spout of
// SyntheticFields.hpp, whose u_P converges onto a few surfaces: after 2 s of process its 472,850
// tracers sit in about 1,100 cells, up to 5,600 per cell, alpha_P of the tracers above 40.
//
// Here the particle flux alpha_P u_P^rec is the curl of a stream function psi(x, y), so it is
// divergence-free and alpha_P^rec is the tracers' stationary density: in a steady field, tracers placed
// by alpha_P stay distributed by alpha_P (continuity), as in a CFD-DEM database, and Eq. (10) only
// corrects discretisation error and the frame-to-frame noise. The picture (uniform along z, mirrored
// about x = 0):
//  - in the V-shaped bottom, up to the bed height H (set so the field holds the scene's bed mass), an
//    annulus (alpha_P 0.45) sliding down the walls and into the spout at its lower half;
//  - a spout near the axis (the inner 30% of the half-width, alpha_P 0.2) carrying particles up at
//    about 2.2 m/s, spreading out over its upper half;
//  - a fountain (alpha_P 0.1) from H to the circulation's top 1.8 H, where they fall back;
//  - the gas at 12 m/s in the spout, 1 m/s through the annulus, 1.3 m/s above (the process air over
//    the chamber's cross-section), the spout's jet decaying over 50 mm above the bed.
// The values were chosen so that the solids move as in the quick example's CFD-DEM database
// (fieldStatistics() in TracerBenchCase.hpp, solids-weighted over all frames; that database / this
// field): 7.4% / 7.5% of the solids move more than one cell per step, 18.7% / 13.5% faster than 1 m/s,
// mean speed 0.58 / 0.57 m/s, 33% / 29% in cells with alpha_P > 0.45 and 40% / 38% below 0.2.
// A steady flux alone would leave the tracers on their streamlines, and the interpolation error of the
// cell-centred field gathers them onto a few (stripes at 1.5x alpha_P within 2 s). So the flow is the
// main circulation plus two more stream-function modes with zero boundary values, oscillating with
// period 0.5 s (the database's 100 frames) out of phase: one moves the spout's feed zone up and down,
// one splits the annulus into two cells and back. Every frame is still divergence-free with the same
// alpha_P, and the time-periodic flow mixes the tracers as a real bed's spout oscillations do. The
// circulation rate pulses by +-25%, and every cell carries 2% noise in alpha_P and 5% in u_P per frame.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "SyntheticFields.hpp"
#include "fields/FieldDatabase.hpp"
#include "scene/Scene.hpp"

namespace rcfd::bench {

class CirculatingBed {
 public:
  static constexpr double kAnnulusAlpha = 0.45;
  static constexpr double kSpoutAlpha = 0.2;
  static constexpr double kFountainAlpha = 0.1;
  static constexpr double kSpoutFraction = 0.3;       ///< spout half-width / chamber half-width [-]
  static constexpr double kSpoutFlux = 0.45;          ///< alpha_P u_P on the axis at mid-height [m/s]
  static constexpr double kTopOverBed = 1.8;          ///< top of the circulation / bed height [-]
  static constexpr double kPulse = 0.25, kPeriod = 0.5;  ///< circulation rate's pulse [-], period [s]
  static constexpr int kModes = 3;
  static constexpr double kFeedModeAmplitude = 0.4, kAnnulusModeAmplitude = 0.3;  ///< of modes 1, 2 [-]
  static constexpr double kStrayFall = -1.0;          ///< u_P above the circulation [m/s]
  /// alpha_P above the circulation: a trace of particles falling back, so that the frames carry their
  /// velocity there (the reader completes u_P only where alpha_P is 0: VelocityCompletion.hpp) [-]
  static constexpr float kStrayAlpha = 1e-6f;

  /// `open`: open fraction of each cell (openFractions()).
  CirculatingBed(const Scene& scene, const CartesianGrid& grid, const std::vector<float>& open)
      : grid_(grid), open_(open) {
    const ApparatusSpec& a = scene.apparatus;
    halfInlet_ = 0.5 * a.inlet_width;
    slope_ = 1.0 / std::tan(a.prism_angle_deg * M_PI / 180.0);
    halfWidth_ = 0.5 * a.width;
    // The bed height that holds the bed's solid volume (bisection; the volume grows with H).
    const double solids = scene.process.bed_mass / scene.particles.density;
    double lo = 0.01, hi = a.height / kTopOverBed;
    for (int it = 0; it < 60; ++it) {
      bedHeight_ = 0.5 * (lo + hi);
      (solidVolume(open) < solids ? lo : hi) = bedHeight_;
    }
    buildMeanFields();
  }

  double bedHeight() const { return bedHeight_; }

  /// Frame n at time t (the AnalyticDatabase's FrameFunction).
  void operator()(int n, double t, FieldFrame& f) const {
    const double phase = 2.0 * M_PI * t / kPeriod;
    const double rate = 1.0 + kPulse * std::sin(phase);
    const std::array<double, kModes> amplitude{rate, rate * kFeedModeAmplitude * std::sin(phase),
                                               rate * kAnnulusModeAmplitude * std::cos(phase)};
    for (std::int64_t c = 0; c < grid_.cellCount(); ++c) {
      const std::size_t s = std::size_t(c);
      const double a = alpha_[s];
      const auto cell = std::uint64_t(c), frame = std::uint64_t(n);
      f.alpha_p[s] = a > 0.0 ? float(std::max(0.0, a + 0.02 * hashNoise(cell, frame))) : (open_[s] > 0.0f ? kStrayAlpha : 0.0f);
      const double wobble = 1.0 + 0.05 * hashNoise(cell, frame + 7919);
      for (int d = 0; d < 2; ++d) {
        double u = 0.0;
        for (int m = 0; m < kModes; ++m) u += amplitude[std::size_t(m)] * up_[std::size_t(m)][2 * s + std::size_t(d)];
        f.u_p[3 * s + std::size_t(d)] = a > 0.0 ? float(wobble * u) : (d == 1 ? float(kStrayFall) : 0.0f);
      }
      f.u_g[3 * s + 1] = ug_[s];
    }
  }

 private:
  /// Half-width of the chamber at height y [m].
  double halfWidthAt(double y) const { return std::min(halfWidth_, halfInlet_ + slope_ * std::max(0.0, y)); }
  double top() const { return kTopOverBed * bedHeight_; }

  /// alpha_P^rec of the cell centred at (x, y) with height dy; cut cells whose centre lies outside the
  /// chamber take the value inside. The row the bed's surface crosses mixes bed and fountain by the
  /// part of the cell below H, so the solid volume grows continuously with H.
  double alphaAt(double x, double y, double dy) const {
    if (y > top()) return 0.0;
    const double bed = std::abs(x) < kSpoutFraction * halfWidthAt(y) ? kSpoutAlpha : kAnnulusAlpha;
    const double below = std::clamp((bedHeight_ - (y - 0.5 * dy)) / dy, 0.0, 1.0);
    return below * bed + (1.0 - below) * kFountainAlpha;
  }

  /// The stream functions for a unit circulation rate, psi_m = -sign(x) A_m(xi) B_m(eta), xi = |x| / w(y),
  /// eta = y / top, all zero on the axis, the walls, the bottom and the top, so no flux leaves the bed.
  /// Mode 0, the circulation: A rises over the spout (0 <= xi < xi_s) and falls over the annulus,
  /// B = sin(pi eta). Mode 1: the same A, B = sin(2 pi eta). Mode 2: A = sin(2 pi (xi - xi_s) / (1 - xi_s))
  /// over the annulus only, B = sin(pi eta).
  double psi(int mode, double x, double y) const {
    const double w = halfWidthAt(y), eta = y / top();
    const double xi = std::abs(x) / w;
    if (eta <= 0.0 || eta >= 1.0 || xi >= 1.0) return 0.0;
    const double s = kSpoutFraction;
    double a = xi < s ? std::sin(0.5 * M_PI * xi / s) : std::cos(0.5 * M_PI * (xi - s) / (1.0 - s));
    if (mode == 2) a = xi < s ? 0.0 : std::sin(2.0 * M_PI * (xi - s) / (1.0 - s));
    const double b = std::sin((mode == 1 ? 2.0 : 1.0) * M_PI * eta);
    return -std::copysign(1.0, x) * a * b;
  }

  double solidVolume(const std::vector<float>& open) const {
    double v = 0.0;
    for (std::int64_t c = 0; c < grid_.cellCount(); ++c) {
      const auto ijk = grid_.cellIjk(c);
      const Eigen::Vector3d p = grid_.cellCenter(ijk[0], ijk[1], ijk[2]);
      v += alphaAt(p.x(), p.y(), grid_.spacing.y()) * double(open[std::size_t(c)]) * grid_.cellVolume();
    }
    return v;
  }

  void buildMeanFields() {
    const std::size_t cells = std::size_t(grid_.cellCount());
    alpha_.assign(cells, 0.0);
    for (auto& u : up_) u.assign(2 * cells, 0.0);
    ug_.assign(cells, 0.0f);
    const double dx = grid_.spacing.x(), dy = grid_.spacing.y();
    // Scale psi so that the flux on the axis at mid-bed is kSpoutFlux.
    const double probeY = 0.5 * bedHeight_, h = 1e-5;
    const double unitFlux = -(psi(0, h, probeY) - psi(0, -h, probeY)) / (2.0 * h);
    const double scale = kSpoutFlux / unitFlux;
    for (std::int64_t c = 0; c < grid_.cellCount(); ++c) {
      const auto ijk = grid_.cellIjk(c);
      const Eigen::Vector3d p = grid_.cellCenter(ijk[0], ijk[1], ijk[2]);
      const std::size_t s = std::size_t(c);
      const double a = alphaAt(p.x(), p.y(), dy);
      alpha_[s] = a;
      // The cell's mean flux from psi at its corners (central differences of the corner values).
      const double x0 = p.x() - 0.5 * dx, x1 = p.x() + 0.5 * dx, y0 = p.y() - 0.5 * dy, y1 = p.y() + 0.5 * dy;
      for (int m = 0; m < kModes && a > 0.0; ++m) {
        const double p00 = psi(m, x0, y0), p10 = psi(m, x1, y0), p01 = psi(m, x0, y1), p11 = psi(m, x1, y1);
        up_[std::size_t(m)][2 * s] = scale * ((p01 + p11) - (p00 + p10)) / (2.0 * dy) / a;
        up_[std::size_t(m)][2 * s + 1] = -scale * ((p10 + p11) - (p00 + p01)) / (2.0 * dx) / a;
      }
      const double w = halfWidthAt(p.y());
      const bool spoutColumn = std::abs(p.x()) < kSpoutFraction * w;
      double ug = 1.3;
      if (p.y() < bedHeight_) ug = spoutColumn ? 12.0 : 1.0;
      else if (spoutColumn) ug = 1.3 + 10.7 * std::exp(-(p.y() - bedHeight_) / 0.05);
      ug_[s] = float(ug);
    }
  }

  CartesianGrid grid_;
  std::vector<float> open_;  ///< open fraction of each cell
  double halfInlet_ = 0.01, slope_ = 0.577, halfWidth_ = 0.125, bedHeight_ = 0.1;
  std::vector<double> alpha_;
  std::array<std::vector<double>, kModes> up_;  ///< (u_x, u_y) per cell of each mode at unit amplitude [m/s]
  std::vector<float> ug_;                       ///< u_G,y per cell [m/s]
};

}  // namespace rcfd::bench
