#include "cfddem/ReferenceRecorder.hpp"

#include <cmath>

#include "analysis/ReferenceStatistics.hpp"
#include "analysis/SeriesSpectrum.hpp"
#include "core/Errors.hpp"
#include "geometry/Apparatus.hpp"
#include "core/Hdf5.hpp"
#include "recurrence/SamplingCriterion.hpp"

namespace rcfd {
namespace {

nlohmann::json numberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

}  // namespace

ReferenceRecorder::ReferenceRecorder(const Scene& scene, const CartesianGrid& grid, std::size_t parcels, double dt,
                                     std::int64_t referenceStart)
    : scene_(scene),
      zone_(scene.spray.spray_zone, Apparatus(scene.apparatus)),
      dt_(dt),
      referenceStart_(referenceStart),
      particlesPerParcel_(std::pow(scene.dem.coarse_graining, 3)),
      stays_(parcels) {
  for (const auto& p : scene.probes) probeCells_.push_back(grid.flatIndexOf(p.position));
}

void ReferenceRecorder::record(const std::vector<Eigen::Vector3d>& particleVelocity, double pressureDrop,
                               const DemParticles& parcels) {
  const std::int64_t s = samples();
  for (const std::int64_t c : probeCells_) probeVelocity_.push_back(particleVelocity.at(std::size_t(c)).y());
  pressureDrop_.push_back(pressureDrop);
  if (s < referenceStart_) return;
  std::int64_t inside = 0;
  std::vector<std::int64_t> finished;
  for (std::size_t i = 0; i < parcels.size(); ++i) {
    const std::uint64_t id = parcels.id[i];
    if (id >= stays_.members()) {
      throw RunError("reference statistics: parcel id " + std::to_string(id) + " beyond the " +
                     std::to_string(stays_.members()) + " parcels of the bed");
    }
    const bool in = zone_.contains(parcels.x[i]);
    inside += in;
    if (s == referenceStart_) {
      if (in) stays_.startInside(std::size_t(id));  // entered before the reference period: not counted
    } else if (const std::int64_t d = stays_.observe(std::size_t(id), in, s, referenceStart_); d >= 0) {
      finished.push_back(d);
    }
  }
  stays_.addDurations(finished);
  holdup_.push_back(inside);
}

std::vector<double> ReferenceRecorder::probeSeries(std::size_t p, std::int64_t first, std::int64_t last) const {
  std::vector<double> out;
  const std::size_t n = probeCells_.size();
  for (std::int64_t s = std::max<std::int64_t>(0, first); s < std::min(last, samples()); ++s) {
    out.push_back(probeVelocity_[std::size_t(s) * n + p]);
  }
  return out;
}

void ReferenceRecorder::save(h5::File& f, const std::string& g) const {
  f.write(g + "/probe_velocity", probeVelocity_);
  f.write(g + "/pressure_drop", pressureDrop_);
  f.write(g + "/holdup", holdup_);
  stays_.save(f, g + "/stays");
}

void ReferenceRecorder::load(const h5::File& f, const std::string& g) {
  probeVelocity_ = f.readDoubles(g + "/probe_velocity");
  pressureDrop_ = f.readDoubles(g + "/pressure_drop");
  holdup_ = f.readInt64s(g + "/holdup");
  stays_.load(f, g + "/stays");
  if (probeVelocity_.size() != pressureDrop_.size() * probeCells_.size()) {
    throw InputError(f.path(), g + "/probe_velocity", "does not match the scene's probes");
  }
}

void ReferenceRecorder::write(h5::File& db) const {
  namespace L = analysis::reference_layout;
  namespace R = reference_series;
  const double t0 = double(referenceStart_) * dt_;
  // The calibration refuses empty reference datasets: leave out what the run did not produce.
  const std::vector<double> durations = stays_.durations(dt_);
  if (!durations.empty()) {
    db.write(L::durations, durations);
    db.setAttribute(L::durations, "dt", dt_);
    // What a crossing rate (stays per member per second) divides by.
    db.setAttribute(L::durations, L::members, double(stays_.members()));
    db.setAttribute(L::durations, L::period, double(holdup_.size()) * dt_);
  }
  if (!holdup_.empty()) {
    std::vector<double> particles(holdup_.size()), parcels(holdup_.size());
    for (std::size_t s = 0; s < holdup_.size(); ++s) {
      parcels[s] = double(holdup_[s]);
      particles[s] = parcels[s] * particlesPerParcel_;
    }
    db.write(L::holdup, particles);
    db.setAttribute(L::holdup, L::holdupDt, dt_);
    db.setAttribute(L::holdup, "t0", t0);
    db.setAttribute(L::holdup, "particles_per_parcel", particlesPerParcel_);
    db.write(R::holdupParcels, parcels);
    db.setAttribute(R::holdupParcels, "dt", dt_);
    db.setAttribute(R::holdupParcels, "t0", t0);
  }
  if (!pressureDrop_.empty()) {
    db.write(R::pressureDrop, pressureDrop_);
    db.setAttribute(R::pressureDrop, "dt", dt_);
    db.setAttribute(R::pressureDrop, "t0", 0.0);
  }
  if (!probeCells_.empty() && samples() > 0) {
    db.write(R::probeVelocity, probeVelocity_, {hsize_t(samples()), hsize_t(probeCells_.size())});
    db.setAttribute(R::probeVelocity, "dt", dt_);
    db.setAttribute(R::probeVelocity, "t0", 0.0);
    nlohmann::json names = nlohmann::json::array();
    std::vector<double> positions;
    for (const auto& p : scene_.probes) {
      names.push_back(p.name);
      positions.insert(positions.end(), {p.position.x(), p.position.y(), p.position.z()});
    }
    db.writeString(R::probeNames, names.dump());
    db.write(R::probePositions, positions, {hsize_t(scene_.probes.size()), 3});
  }
  db.createGroup("/reference");
  db.setAttribute("/reference", "dt", dt_);
  db.setAttribute("/reference", "reference_t0", t0);
}

nlohmann::json ReferenceRecorder::summary(double dtRec, int residenceTimeBins) const {
  nlohmann::json out;
  nlohmann::json rt = stays_.statistics(dt_, residenceTimeBins).toJson();
  rt["sample_dt_s"] = dt_;
  rt["durations_file"] = std::string("database.h5:") + analysis::reference_layout::durations;
  out["residence_time"] = rt;
  double mean = 0.0;
  for (const auto h : holdup_) mean += double(h);
  mean = holdup_.empty() ? 0.0 : mean / double(holdup_.size());
  out["holdup"] = {{"mean", mean * particlesPerParcel_},
                   {"mean_parcels", mean},
                   {"particles_per_parcel", particlesPerParcel_},
                   {"mean_fraction", stays_.members() ? mean / double(stays_.members()) : 0.0},
                   {"series_file", std::string("database.h5:") + analysis::reference_layout::holdup}};

  nlohmann::json dp = {{"samples", samples()}, {"dt_s", dt_},
                       {"series_file", std::string("database.h5:") + reference_series::pressureDrop}};
  constexpr std::int64_t kSpectrumSamples = 4;
  if (samples() >= kSpectrumSamples) {
    const auto s = analysis::seriesSpectrum(pressureDrop_, dt_);
    dp["mean_pa"] = s.mean;
    dp["std_pa"] = s.std;
    dp["dominant_frequency_hz"] = s.dominantFrequency ? nlohmann::json(*s.dominantFrequency) : nlohmann::json();
    dp["frequency_resolution_hz"] = s.resolution;
  } else {
    dp["mean_pa"] = nullptr;
    dp["std_pa"] = nullptr;
    dp["dominant_frequency_hz"] = nullptr;
  }
  out["pressure_drop"] = dp;

  // Eq. (8) from each probe's u_P,y over the sampled period, sampled every dt_ < dt_rec.
  nlohmann::json probes = nlohmann::json::array();
  double admissible = std::numeric_limits<double>::infinity();
  const std::int64_t sampled = std::min(referenceStart_, samples());
  for (std::size_t p = 0; p < probeCells_.size() && sampled >= 3; ++p) {
    const double bound = samplingBound(probeSeries(p, 0, sampled), dt_);
    probes.push_back({{"name", scene_.probes[p].name}, {"bound_s", numberOrNull(bound)}});
    admissible = std::min(admissible, bound);
  }
  out["sampling_criterion"] = {{"field", "u_p.y"},
                               {"signal_dt_s", dt_},
                               {"dt_rec_s", dtRec},
                               {"probes", probes},
                               {"largest_admissible_dt_rec_s", numberOrNull(admissible)},
                               {"satisfied", probes.empty() ? nlohmann::json() : nlohmann::json(dtRec < admissible)}};
  return out;
}

}  // namespace rcfd
