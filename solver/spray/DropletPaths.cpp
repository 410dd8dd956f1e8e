#include "spray/DropletPaths.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "core/Errors.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/ThinWalls.hpp"
#include "spray/Coverage.hpp"
#include "spray/DepositionEfficiency.hpp"
#include "spray/SprayLaunch.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/FrameSampler.hpp"

namespace rcfd {
namespace {

/// What one path did: the share of its droplets that ended where, and its survival on first reaching
/// each height (NaN: never reached).
struct PathEnd {
  double outlet = 0.0, wall = 0.0, airborne = 0.0;
  double survival = 1.0;
  std::vector<double> survivalAt;
};

class PathTracer {
 public:
  PathTracer(const Scene& scene, const FieldDatabase& db, const DropletPathOptions& o)
      : scene_(scene), db_(db), o_(o), apparatus_(scene.apparatus), grid_(db.grid()),
        plates_(plateFacesAbove(apparatus_, grid_)), model_(DepositionModelRegistry::create(scene.spray.deposition_model)),
        constants_(depositionConstants(scene)),
        cosHalfAngle_(std::cos(scene.spray.cone_half_angle_deg * std::numbers::pi / 180.0)),
        minSpacing_(grid_.spacing.minCoeff()) {}

  /// The path `index` launched at frame `first`.
  PathEnd trace(int first, std::uint64_t index) const {
    CounterRng rng(o_.seed, RngPurpose::SprayInjection, index, 0);
    const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
    Eigen::Vector3d p = sprayLaunchPoint(scene_.spray, cosHalfAngle_, minSpacing_, u1, u2, u3);
    PathEnd end;
    end.survivalAt.assign(o_.heights.size(), std::numeric_limits<double>::quiet_NaN());
    if (!(apparatus_.signedDistance(p) > 0.0)) {  // the cone starts in a wall, as the spray effect counts it
      end.wall = 1.0;
      return end;
    }
    const double dtRec = db_.dtRec();
    const std::uint8_t* plates = plates_.empty() ? nullptr : plates_.data();
    double t = 0.0;
    double survival = 1.0;
    int held = -1;  // the frame interval whose two frames a and b hold
    std::shared_ptr<const FieldFrame> a, b;
    while (t < o_.maxSeconds) {
      const double frames = t / dtRec;
      const int k = int(std::floor(frames));
      if (k != held) a = db_.frame(first + k), b = db_.frame(first + k + 1), held = k;
      const FrameSampler fields(grid_, a.get(), b.get(), frames - k, plates);
      const Eigen::Vector3d u = fields.velocity(p, true);
      // At most half a cell per sub-step, and none across a frame interval's end or the time limit.
      const double toFrameEnd = std::max((k + 1) * dtRec - t, 1e-12 * dtRec);
      double h = std::min(toFrameEnd, o_.maxSeconds - t);
      const double speed = u.norm();
      if (speed > 0.0) h = std::min(h, 0.5 * minSpacing_ / speed);
      Eigen::Vector3d at = p + h * u;
      double seconds = h;
      int exit = 0;  // 1 wall, 2 outlet
      if (const auto hit = apparatus_.firstIntersection(p, at)) {
        seconds = h * hit->t;
        at = hit->point;
        exit = hit->kind == BoundaryKind::Outlet ? 2 : 1;
      }
      if (seconds > 0.0) {
        const Eigen::Vector3d mid = 0.5 * (p + at);
        const double alphaP = fields.alphaP(grid_.flatIndexOf(mid));
        if (alphaP > 0.0) {
          const double slip = (fields.velocity(mid, true) - fields.velocity(mid, false)).norm();
          survival *= 1.0 - model_->efficiency({alphaP, slip, seconds}, constants_);  // Eq. (11)-(14)
        }
      }
      p = at;
      t += seconds;
      for (std::size_t j = 0; j < o_.heights.size(); ++j) {
        if (std::isnan(end.survivalAt[j]) && p.y() >= o_.heights[j]) end.survivalAt[j] = survival;
      }
      if (exit == 2) end.outlet = survival;
      if (exit == 1) end.wall = survival;
      if (exit != 0) break;
    }
    if (t >= o_.maxSeconds && end.outlet == 0.0 && end.wall == 0.0) end.airborne = survival;
    end.survival = survival;
    return end;
  }

 private:
  const Scene& scene_;
  const FieldDatabase& db_;
  const DropletPathOptions& o_;
  Apparatus apparatus_;
  const CartesianGrid& grid_;
  std::vector<std::uint8_t> plates_;
  std::unique_ptr<DepositionModel> model_;
  DepositionConstants constants_;
  double cosHalfAngle_;
  double minSpacing_;
};

/// Paths and heights of one call: every path's survival at every height is kept for the quantiles.
constexpr std::int64_t kMaxPaths = 1000000;
constexpr std::size_t kMaxHeights = 100;

/// Survival below this reads as this (an optical depth of 708): every droplet caught.
constexpr double kLeastSurvival = std::numeric_limits<double>::min();

void check(bool ok, const std::string& pointer, const std::string& message) {
  if (!ok) throw InputError("droplet paths", pointer, message);
}

}  // namespace

DropletPathReport dropletPaths(const Scene& scene, const FieldDatabase& db, const DropletPathOptions& o) {
  check(o.launches >= 1 && o.launches <= 100000, "/launches", "must be in [1, 100000]");
  check(o.pathsPerLaunch >= 1 && o.pathsPerLaunch <= 100000, "/paths_per_launch", "must be in [1, 100000]");
  check(std::int64_t(o.launches) * o.pathsPerLaunch <= kMaxPaths, "/paths_per_launch",
        "launches x paths per launch must not exceed " + std::to_string(kMaxPaths) + " (every path's ends are kept)");
  check(o.heights.size() <= kMaxHeights, "/heights", "at most " + std::to_string(kMaxHeights) + " heights");
  check(std::isfinite(o.maxSeconds) && o.maxSeconds > 0.0, "/max_seconds", "must be a positive number of seconds");
  // A path reads the frame after the one it is in: maxSeconds spans this many frame intervals.
  const int span = int(std::ceil(o.maxSeconds / db.dtRec())) + 1;
  check(span < db.frameCount(), "/max_seconds",
        "the database's " + std::to_string(db.frameCount()) + " frames of " + std::to_string(db.dtRec()) +
            " s hold at most " + std::to_string((db.frameCount() - 2) * db.dtRec()) + " s of flight");
  for (std::size_t j = 0; j < o.heights.size(); ++j) {
    check(std::isfinite(o.heights[j]), "/heights/" + std::to_string(j), "must be a finite height [m]");
  }
  const PathTracer tracer(scene, db, o);
  const int lastFirst = db.frameCount() - 1 - span;
  const std::int64_t paths = std::int64_t(o.launches) * o.pathsPerLaunch;
  std::vector<PathEnd> ends(static_cast<std::size_t>(paths));
  // A frame that fails to load (NaN found by a cached database) throws after the loop: exceptions must
  // not leave an OpenMP region.
  std::exception_ptr failure;
  // Paths are independent and each draws from its own counter stream: any thread count, same result.
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t i = 0; i < paths; ++i) {
    const int launch = int(i / o.pathsPerLaunch);
    const int first = o.launches == 1 ? 0 : int(std::llround(double(launch) * lastFirst / (o.launches - 1)));
    try {
      ends[std::size_t(i)] = tracer.trace(first, std::uint64_t(i));
    } catch (...) {
#pragma omp critical(rcfd_droplet_paths_failure)
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);

  DropletPathReport r;
  r.launches = o.launches;
  r.pathsPerLaunch = o.pathsPerLaunch;
  r.maxSeconds = o.maxSeconds;
  std::vector<double> perLaunch(std::size_t(o.launches), 0.0);
  for (std::int64_t i = 0; i < paths; ++i) {
    const PathEnd& e = ends[std::size_t(i)];
    r.outlet += e.outlet, r.wall += e.wall, r.airborne += e.airborne;
    perLaunch[std::size_t(i / o.pathsPerLaunch)] += (e.outlet + e.wall) / o.pathsPerLaunch;
  }
  r.outlet /= double(paths), r.wall /= double(paths), r.airborne /= double(paths);
  r.deposited = std::max(0.0, 1.0 - r.outlet - r.wall - r.airborne);
  r.launchesAbove1e3 = double(std::count_if(perLaunch.begin(), perLaunch.end(), [](double v) { return v > 1e-3; })) /
                       double(o.launches);
  r.launchOversprayMax = *std::max_element(perLaunch.begin(), perLaunch.end());
  const Distribution launches = describe(perLaunch, 1, 0.0, 1.0);
  r.launchOversprayMedian = launches.median;
  r.launchOversprayP90 = launches.p90;

  for (std::size_t j = 0; j < o.heights.size(); ++j) {
    DropletPathHeight h;
    h.y = o.heights[j];
    std::vector<double> depth;
    double below = 0.0;
    for (const PathEnd& e : ends) {
      const double s = e.survivalAt[j];
      if (std::isnan(s)) {
        below += 1.0 - e.survival;  // all it deposited, it deposited below y
        continue;
      }
      below += 1.0 - s;
      depth.push_back(s > kLeastSurvival ? -std::log(s) : -std::log(kLeastSurvival));
    }
    h.reached = double(depth.size()) / double(paths);
    h.depositedBelow = below / double(paths);
    if (!depth.empty()) {
      const Distribution d = describe(std::move(depth), 1, 0.0, 1.0);
      h.opticalDepthP10 = d.p10, h.opticalDepthMedian = d.median, h.opticalDepthP90 = d.p90;
    }
    r.heights.push_back(h);
  }
  return r;
}

}  // namespace rcfd
