#include "cfddem/DemFilling.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <spdlog/spdlog.h>
#include <unordered_map>

#include "core/Errors.hpp"

namespace rcfd {

using Eigen::Vector3d;

long parcelsForBedMass(const Scene& scene) {
  const double d = scene.particles.diameter;
  const double m_particle = std::numbers::pi / 6.0 * d * d * d * scene.particles.density;
  const double cg = scene.dem.coarse_graining;
  return std::lround(scene.process.bed_mass / (cg * cg * cg * m_particle));
}

FillRegion defaultFillRegion(const ApparatusSpec& a) {
  FillRegion r;
  if (a.type == ApparatusSpec::Type::Box) {
    r.lower = Vector3d(-0.5 * a.size.x(), 2.0 / 3.0 * a.size.y(), 0.0);
    r.upper = Vector3d(0.5 * a.size.x(), a.size.y(), a.size.z());
  } else if (a.height >= 0.3) {
    r.lower = Vector3d(-0.5 * a.width, 0.2, 0.0);
    r.upper = Vector3d(0.5 * a.width, 0.3, a.depth);
  } else {
    // A chamber lower than the paper's region: its upper third, and above the top of the V-bottom.
    const double vTop = 0.5 * (a.width - a.inlet_width) * std::tan(a.prism_angle_deg * std::numbers::pi / 180.0);
    r.lower = Vector3d(-0.5 * a.width, std::max(2.0 / 3.0 * a.height, vTop), 0.0);
    r.upper = Vector3d(0.5 * a.width, a.height, a.depth);
  }
  return r;
}

namespace {
/// DEM steps of about one millisecond: how often settling looks at the kinetic energy.
long stepsPerMillisecond(const DemSystem& dem) { return std::max(1L, static_cast<long>(1e-3 / dem.timeStep())); }

void throwIfStopRequested(const DemSystem& dem, const std::function<bool()>& stop_requested) {
  if (stop_requested && stop_requested())
    throw Cancelled("stopped while filling and settling the bed at t = " + std::to_string(dem.time()) +
                    " s; nothing is kept: the next run fills again");
}

/// `steps` DEM steps with a look at the stop request and a call of `before(s)` before each.
void runStoppable(DemSystem& dem, long steps, const std::function<bool()>& stop_requested,
                  const std::function<void(long)>& before = {}) {
  for (long s = 0; s < steps; ++s) {
    throwIfStopRequested(dem, stop_requested);
    if (before) before(s);
    dem.step();
  }
}
}  // namespace

double fillSettleFraction(double time, double maxTime, double energy, double firstEnergy, double settledEnergy) {
  double f = maxTime > 0.0 ? time / maxTime : 1.0;
  if (energy <= settledEnergy) return 1.0;
  if (firstEnergy > settledEnergy && energy < firstEnergy)
    f = std::max(f, std::log(firstEnergy / energy) / std::log(firstEnergy / settledEnergy));
  return std::clamp(f, 0.0, 1.0);
}

long fallStepsPerBatch(const DemSystem& dem, const FillRegion& region) {
  const double r = dem.material().particle_radius;
  const double g = dem.settings().gravity.norm();
  const double height = region.upper.y() - region.lower.y();
  const double fall_time = g > 0.0 ? std::sqrt(2.0 * (height + 2.0 * r) / g) : 0.0;
  return std::max(1L, std::lround(fall_time / dem.timeStep()));
}

double settle(DemSystem& dem, double max_time, double fraction, bool* settled,
              const std::function<bool()>& stop_requested, const std::function<void(double)>& progress) {
  const DemParticles& p = dem.particles();
  const double g = dem.settings().gravity.norm();
  const double t0 = dem.time();
  const long check = stepsPerMillisecond(dem);
  bool ok = false;
  double firstEnergy = -1.0, reached = 0.0;
  std::function<void(long)> report;
  if (progress) {
    report = [&](long) {
      reached = std::max(reached, max_time > 0.0 ? std::min(1.0, (dem.time() - t0) / max_time) : 1.0);
      progress(reached);
    };
  }
  while (dem.time() - t0 < max_time) {
    runStoppable(dem, check, stop_requested, report);
    double ref = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) ref += p.mass[i] * g * p.radius[i];
    const double energy = p.kineticEnergy();
    if (p.size() == 0 || energy < fraction * ref) {
      ok = true;
      break;
    }
    if (firstEnergy < 0.0) firstEnergy = energy;
    reached = std::max(reached, fillSettleFraction(dem.time() - t0, max_time, energy, firstEnergy, fraction * ref));
  }
  if (progress) progress(1.0);
  if (settled) *settled = ok;
  return dem.time() - t0;
}

namespace {

/// Hash of occupied cells of edge 2 r for the overlap test of new parcels.
struct Occupancy {
  double cell;
  std::unordered_map<long long, std::vector<Vector3d>> cells;
  long long key(long i, long j, long k) const {
    return (i + (1LL << 20)) * (1LL << 42) + (j + (1LL << 20)) * (1LL << 21) + (k + (1LL << 20));
  }
  void add(const Vector3d& x) {
    cells[key(std::lround(std::floor(x.x() / cell)), std::lround(std::floor(x.y() / cell)),
               std::lround(std::floor(x.z() / cell)))].push_back(x);
  }
  bool free(const Vector3d& x, double min_dist) const {
    const long ci = std::lround(std::floor(x.x() / cell)), cj = std::lround(std::floor(x.y() / cell)),
               ck = std::lround(std::floor(x.z() / cell));
    for (long i = ci - 1; i <= ci + 1; ++i)
      for (long j = cj - 1; j <= cj + 1; ++j)
        for (long k = ck - 1; k <= ck + 1; ++k) {
          auto it = cells.find(key(i, j, k));
          if (it == cells.end()) continue;
          for (const Vector3d& y : it->second)
            if ((x - y).squaredNorm() < min_dist * min_dist) return false;
        }
    return true;
  }
};

}  // namespace

FillResult fillAndSettle(DemSystem& dem, const FillRegion& region, long count, const FillOptions& o) {
  FillResult result;
  const double r = dem.material().particle_radius;
  const double g = dem.settings().gravity.norm();
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Vector3d lo = region.lower + Vector3d::Constant(r), hi = region.upper - Vector3d::Constant(r);
  if ((hi.array() <= lo.array()).any())
    throw RunError("DEM filling: the insertion region is smaller than a parcel");
  // A batch falls clear of the region in about sqrt(2 h / g) (plus one diameter).
  const long fall_steps = fallStepsPerBatch(dem, region);
  const double t0 = dem.time();
  const double gap = 1.02 * 2.0 * r;  // parcels start just clear of each other
  if (o.stage_started) o.stage_started(FillStage::Inserting);
  // Progress of the insertion in parcel DEM steps, the DEM's work, against the work expected once the
  // first batch shows how many parcels a batch takes (each later one as many, the last the rest): a
  // batch falls as long as the first, with every parcel inserted so far. Held below 1 until the last
  // batch has fallen, in case the region takes fewer parcels as the bed rises into it.
  constexpr double kBeforeTheEnd = 0.999;
  double work_done = 0.0, work_expected = 0.0, reported = 0.0;
  auto inserting = [&](double fall_work) {
    if (!o.progress || !(work_expected > 0.0)) return;
    reported = std::max(reported, std::min(kBeforeTheEnd, (work_done + fall_work) / work_expected));
    o.progress(FillStage::Inserting, reported);
  };
  if (o.progress) o.progress(FillStage::Inserting, 0.0);
  while (result.inserted < count) {
    if (result.batches >= o.max_batches)
      throw RunError("DEM filling: " + std::to_string(count - result.inserted) + " of " +
                     std::to_string(count) + " parcels found no room after " + std::to_string(o.max_batches) +
                     " batches: the bed does not pour into the chamber below the filling region (a smaller "
                     "/process/bed_mass fits; docs/dem.md)");
    ++result.batches;
    Occupancy occ{2.0 * r, {}};
    const DemParticles& p = dem.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if ((p.x[i].array() > region.lower.array() - 2 * r).all() &&
          (p.x[i].array() < region.upper.array() + 2 * r).all())
        occ.add(p.x[i]);
    throwIfStopRequested(dem, o.stop_requested);
    inserting(0.0);
    long misses = 0, batch = 0;
    const long max_misses = 2000 + 20 * (count - result.inserted);
    for (long attempts = 1; result.inserted < count && misses < max_misses; ++attempts) {
      if (attempts % kInsertionAttemptsPerPoll == 0) {
        throwIfStopRequested(dem, o.stop_requested);
        inserting(0.0);
      }
      const Vector3d x = lo + (hi - lo).cwiseProduct(Vector3d(u(rng), u(rng), u(rng)));
      if (dem.walls().clearance(x) < 1.01 * r || (o.inside && !o.inside(x)) || !occ.free(x, gap)) {
        ++misses;
        continue;
      }
      occ.add(x);
      dem.addParticle(x);
      ++result.inserted;
      ++batch;
    }
    spdlog::debug("DEM filling: batch {} inserted {} parcels ({} of {})", result.batches, batch,
                  result.inserted, count);
    if (batch == 0 && g == 0.0) throw RunError("DEM filling: no room and no gravity to make room");
    // Let the batch fall clear (after the last one too, so settling starts with the bed in motion).
    if (!(work_expected > 0.0) && batch > 0) {
      for (long in = 0; in < count;) {
        in = std::min(count, in + batch);
        work_expected += double(in) * double(fall_steps);
      }
    }
    const double present = double(dem.particles().size());
    runStoppable(dem, fall_steps, o.stop_requested, [&](long s) { inserting(double(s) * present); });
    work_done += double(fall_steps) * present;
  }
  if (o.progress) o.progress(FillStage::Inserting, 1.0);  // every parcel in and fallen
  result.fill_time = dem.time() - t0;
  if (o.stage_started) o.stage_started(FillStage::Settling);
  std::function<void(double)> settling;
  if (o.progress) settling = [&](double f) { o.progress(FillStage::Settling, f); };
  result.settle_time = settle(dem, o.max_settle_time, o.settled_energy_fraction, &result.settled, o.stop_requested,
                              settling);
  result.kinetic_energy = dem.particles().kineticEnergy();
  spdlog::info("DEM filling: {} parcels in {} batches, {:.3f} s falling + {:.3f} s settling, {}",
               result.inserted, result.batches, result.fill_time, result.settle_time,
               result.settled ? "settled" : "not settled (time limit)");
  return result;
}

}  // namespace rcfd
