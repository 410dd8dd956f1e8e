#include "analysis/CoverageComparison.hpp"

#include <cmath>
#include <limits>

#include "analysis/KsDistance.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "spray/Coverage.hpp"

namespace rcfd::analysis {
namespace {

nlohmann::json numberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

std::vector<double> coverageValues(const std::vector<double>& dropletsPerParticle, double f) {
  std::vector<double> phi(dropletsPerParticle.size());
  for (std::size_t i = 0; i < phi.size(); ++i) phi[i] = coverage(dropletsPerParticle[i], f);
  return phi;
}

nlohmann::json toJson(const CoverageSummary& s) {
  return {{"members", s.members},
          {"particles_per_member", s.particlesPerMember},
          {"droplets_per_particle_mean", s.dropletsPerParticleMean},
          {"mean", s.mean},
          {"median", s.median},
          {"p10", s.p10},
          {"p90", s.p90}};
}

}  // namespace

std::optional<ReferenceCoverageData> readReferenceCoverage(const std::string& path) {
  namespace L = reference_layout;
  h5::File f(path, h5::File::Mode::ReadOnly);
  if (!f.exists(L::coverageDroplets)) return std::nullopt;
  ReferenceCoverageData r;
  r.dropletsPerParticle = f.readDoubles(L::coverageDroplets);
  if (r.dropletsPerParticle.empty()) throw InputError(path, L::coverageDroplets, "is empty");
  for (std::size_t i = 0; i < r.dropletsPerParticle.size(); ++i) {
    const double v = r.dropletsPerParticle[i];
    if (!std::isfinite(v) || v < 0.0) {
      throw InputError(path, L::coverageDroplets,
                       "entry " + std::to_string(i) + " is " + std::to_string(v) + "; values must be finite and >= 0");
    }
  }
  auto positive = [&](const char* name) {
    if (!f.hasAttribute(L::coverageDroplets, name)) {
      throw InputError(path, std::string(L::coverageDroplets) + "@" + name, "attribute missing");
    }
    const double v = f.doubleAttribute(L::coverageDroplets, name);
    if (!std::isfinite(v) || !(v > 0.0)) {
      throw InputError(path, std::string(L::coverageDroplets) + "@" + name,
                       "is " + std::to_string(v) + "; must be finite and > 0");
    }
    return v;
  };
  r.duration = positive(L::coverageDuration);
  r.dt = positive(L::coverageDt);
  r.particlesPerParcel = positive(L::coverageParticlesPerParcel);
  r.singleDropletCoverage = positive(L::coverageSingleDroplet);
  return r;
}

CoverageSummary summariseCoverage(const std::vector<double>& dropletsPerParticle, double particlesPerMember,
                                  double f) {
  CoverageSummary s;
  s.members = double(dropletsPerParticle.size());
  s.particlesPerMember = particlesPerMember;
  double sum = 0.0;
  for (const double n : dropletsPerParticle) sum += n;
  s.dropletsPerParticleMean = dropletsPerParticle.empty() ? 0.0 : sum / s.members;
  const Distribution d = describe(coverageValues(dropletsPerParticle, f), 1, 0.0, 1.0);
  s.mean = d.mean, s.median = d.median, s.p10 = d.p10, s.p90 = d.p90;
  return s;
}

double CoverageComparison::relativeError(double runValue, double referenceValue) const {
  return referenceValue != 0.0 ? (runValue - referenceValue) / referenceValue
                               : std::numeric_limits<double>::quiet_NaN();
}

nlohmann::json CoverageComparison::toJson() const {
  nlohmann::json j = {{"run_duration_s", runDuration},
                      {"reference_duration_s", referenceDuration},
                      {"same_duration", sameDuration},
                      {"run", analysis::toJson(run)},
                      {"reference", analysis::toJson(reference)}};
  if (!sameDuration) {
    j["note"] = "the run covers another duration than the reference: run the spray job for the reference's "
                "duration to compare the distributions";
    return j;
  }
  j["ks_distance"] = ksDistance;
  j["mean_relative_error"] = numberOrNull(relativeError(run.mean, reference.mean));
  j["p10_relative_error"] = numberOrNull(relativeError(run.p10, reference.p10));
  j["p90_relative_error"] = numberOrNull(relativeError(run.p90, reference.p90));
  j["droplets_per_particle_relative_error"] =
      numberOrNull(relativeError(run.dropletsPerParticleMean, reference.dropletsPerParticleMean));
  const double representation = run.particlesPerMember / reference.particlesPerMember;
  if (std::abs(representation - 1.0) > 0.05) {
    j["note"] = "each tracer stands for " + std::to_string(representation) +
                " x the particles of a parcel: averaging over more particles narrows the distribution; "
                "use one tracer per parcel for a like-for-like comparison";
  }
  return j;
}

CoverageComparison compareCoverage(const std::vector<double>& runDropletsPerParticle, double particlesPerTracer,
                                   double runDuration, double runDt, double f, const ReferenceCoverageData& ref) {
  if (std::abs(f - ref.singleDropletCoverage) > 1e-9 * ref.singleDropletCoverage) {
    throw InputError("database", reference_layout::coverageDroplets,
                     "was sprayed with droplets covering f = " + std::to_string(ref.singleDropletCoverage) +
                         " of a particle each, the scene's cover f = " + std::to_string(f) +
                         " (spray.droplet_diameter / particles.diameter differ): not comparable");
  }
  CoverageComparison c;
  c.runDuration = runDuration;
  c.referenceDuration = ref.duration;
  c.sameDuration = std::abs(runDuration - ref.duration) <= 0.5 * std::max(runDt, ref.dt) + 1e-12;
  c.run = summariseCoverage(runDropletsPerParticle, particlesPerTracer, f);
  c.reference = summariseCoverage(ref.dropletsPerParticle, ref.particlesPerParcel, f);
  if (c.sameDuration && !runDropletsPerParticle.empty()) {
    c.ksDistance = analysis::ksDistance(coverageValues(runDropletsPerParticle, f),
                                        coverageValues(ref.dropletsPerParticle, f));
  }
  return c;
}

}  // namespace rcfd::analysis
