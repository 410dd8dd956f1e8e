#include "cfddem/ReferenceRecorder.hpp"

#include <cmath>

#include "analysis/ReferenceStatistics.hpp"
#include "analysis/SeriesSpectrum.hpp"
#include "analysis/StayComparison.hpp"
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
      stays_(parcels),
      sampledStays_(parcels) {
  for (const auto& p : scene.probes) probeCells_.push_back(grid.flatIndexOf(p.position));
}

void ReferenceRecorder::record(const std::vector<Eigen::Vector3d>& particleVelocity, double pressureDrop,
                               const DemParticles& parcels) {
  const std::int64_t s = samples();
  for (const std::int64_t c : probeCells_) probeVelocity_.push_back(particleVelocity.at(std::size_t(c)).y());
  pressureDrop_.push_back(pressureDrop);
  if (s < referenceStart_) {
    observeZone(parcels, s, 0, sampledStays_, sampledHoldup_);
  } else {
    observeZone(parcels, s, referenceStart_, stays_, holdup_);
  }
}

void ReferenceRecorder::observeZone(const DemParticles& parcels, std::int64_t s, std::int64_t countFrom,
                                    ZoneStays& stays, std::vector<std::int64_t>& holdup) {
  std::int64_t inside = 0;
  std::vector<std::int64_t> finished;
  for (std::size_t i = 0; i < parcels.size(); ++i) {
    const std::uint64_t id = parcels.id[i];
    if (id >= stays.members()) {
      throw RunError("reference statistics: parcel id " + std::to_string(id) + " beyond the " +
                     std::to_string(stays.members()) + " parcels of the bed");
    }
    const bool in = zone_.contains(parcels.x[i]);
    inside += in;
    if (s == countFrom) {
      if (in) stays.startInside(std::size_t(id));  // entered before the period: not counted
    } else if (const std::int64_t d = stays.observe(std::size_t(id), in, s, countFrom); d >= 0) {
      finished.push_back(d);
    }
  }
  stays.addDurations(finished);
  holdup.push_back(inside);
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
  f.write(g + "/sampled_holdup", sampledHoldup_);
  sampledStays_.save(f, g + "/sampled_stays");
}

void ReferenceRecorder::load(const h5::File& f, const std::string& g) {
  probeVelocity_ = f.readDoubles(g + "/probe_velocity");
  pressureDrop_ = f.readDoubles(g + "/pressure_drop");
  holdup_ = f.readInt64s(g + "/holdup");
  stays_.load(f, g + "/stays");
  // A checkpoint written before the sampled period was recorded resumes without it.
  sampledRecorded_ = f.exists(g + "/sampled_holdup");
  if (sampledRecorded_) {
    sampledHoldup_ = f.readInt64s(g + "/sampled_holdup");
    sampledStays_.load(f, g + "/sampled_stays");
  } else {
    sampledHoldup_.clear();
  }
  if (probeVelocity_.size() != pressureDrop_.size() * probeCells_.size()) {
    throw InputError(f.path(), g + "/probe_velocity", "does not match the scene's probes");
  }
}

void ReferenceRecorder::write(h5::File& db) const {
  namespace L = analysis::reference_layout;
  namespace R = reference_series;
  const double t0 = double(referenceStart_) * dt_;
  // One period's stays and holdup [particles] in the layout of analysis/ReferenceStatistics.hpp. The
  // calibration refuses empty reference datasets: leave out what the run did not produce.
  auto writePeriod = [&](const char* durationsName, const char* holdupName, const ZoneStays& stays,
                         const std::vector<std::int64_t>& holdup, double start) {
    const std::vector<double> durations = stays.durations(dt_);
    if (!durations.empty()) {
      db.write(durationsName, durations);
      db.setAttribute(durationsName, "dt", dt_);
      // What a crossing rate (stays per member per second) divides by.
      db.setAttribute(durationsName, L::members, double(stays.members()));
      db.setAttribute(durationsName, L::period, double(holdup.size()) * dt_);
    }
    if (holdup.empty()) return;
    std::vector<double> particles(holdup.size());
    for (std::size_t s = 0; s < holdup.size(); ++s) particles[s] = double(holdup[s]) * particlesPerParcel_;
    db.write(holdupName, particles);
    db.setAttribute(holdupName, L::holdupDt, dt_);
    db.setAttribute(holdupName, "t0", start);
    db.setAttribute(holdupName, "particles_per_parcel", particlesPerParcel_);
  };
  writePeriod(L::durations, L::holdup, stays_, holdup_, t0);
  if (!holdup_.empty()) {
    db.write(R::holdupParcels, std::vector<double>(holdup_.begin(), holdup_.end()));
    db.setAttribute(R::holdupParcels, "dt", dt_);
    db.setAttribute(R::holdupParcels, "t0", t0);
  }
  if (sampledPeriodRecorded()) writePeriod(L::sampledDurations, L::sampledHoldup, sampledStays_, sampledHoldup_, 0.0);
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

nlohmann::json ReferenceRecorder::periodsSummary() const {
  if (!sampledPeriodRecorded() || holdup_.empty()) return nullptr;
  auto mean = [](const std::vector<std::int64_t>& v) {
    double sum = 0.0;
    for (const auto h : v) sum += double(h);
    return sum / double(v.size());
  };
  const double sampledHoldup = mean(sampledHoldup_) * particlesPerParcel_;
  const double referenceHoldup = mean(holdup_) * particlesPerParcel_;
  const double members = double(stays_.members());
  const auto c = analysis::compareStays(sampledStays_.durationCounts(), dt_, members,
                                        double(sampledHoldup_.size()) * dt_, stays_.durations(dt_), members,
                                        double(holdup_.size()) * dt_);
  // The comparison's "tracers" side is the sampled period here.
  nlohmann::json stays = c.toJson();
  stays["resolution"] = "both periods on the recorder's lattice";
  stays["sampled_period"] = stays["tracers"];
  stays["reference_period"] = stays["reference"];
  stays.erase("tracers");
  stays.erase("reference");
  stays["window"]["sampled_period_s"] = stays["window"]["tracers_s"];
  stays["window"]["sampled_period_beyond_fraction"] = stays["window"]["tracers_beyond_fraction"];
  stays["window"].erase("tracers_s");
  stays["window"].erase("tracers_beyond_fraction");
  return {{"what", "the full simulation's sampled period (the frames') against its reference period: how far "
                   "two of its periods differ"},
          {"sampled_period_holdup_mean", sampledHoldup},
          {"reference_period_holdup_mean", referenceHoldup},
          {"holdup_relative_difference", numberOrNull((sampledHoldup - referenceHoldup) / referenceHoldup)},
          {"stays", stays},
          {"sampled_period_files",
           {std::string("database.h5:") + analysis::reference_layout::sampledDurations,
            std::string("database.h5:") + analysis::reference_layout::sampledHoldup}}};
}

nlohmann::json pressureDropSummary(const std::vector<double>& pa, double dt) {
  nlohmann::json dp = {{"samples", pa.size()}, {"dt_s", dt},
                       {"series_file", std::string("database.h5:") + reference_series::pressureDrop}};
  constexpr std::size_t kSpectrumSamples = 4;
  if (pa.size() >= kSpectrumSamples) {
    const auto s = analysis::seriesSpectrum(pa, dt);
    dp["mean_pa"] = s.mean;
    dp["std_pa"] = s.std;
    dp["dominant_frequency_hz"] = s.dominantFrequency ? nlohmann::json(*s.dominantFrequency) : nlohmann::json();
    dp["frequency_resolution_hz"] = s.resolution;
  } else {
    dp["mean_pa"] = nullptr;
    dp["std_pa"] = nullptr;
    dp["dominant_frequency_hz"] = nullptr;
  }
  return dp;
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

  out["pressure_drop"] = pressureDropSummary(pressureDrop_, dt_);
  out["periods"] = periodsSummary();

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
