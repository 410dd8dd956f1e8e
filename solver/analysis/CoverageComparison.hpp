#pragma once
/// \file CoverageComparison.hpp
/// The coverage distribution of an rCFD spray run against the full simulation's own over the same
/// duration (the reference coverage the database job records, spray/ReferenceCoverage.hpp). Both sides
/// apply Eq. (15) to droplets per real particle; a fair comparison has each tracer stand for as many
/// particles as a parcel (one tracer per parcel), since averaging over more particles narrows the
/// distribution. The comparison says when the run's duration or representation differs.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace rcfd::analysis {

/// /reference/coverage/ of a database file.
struct ReferenceCoverageData {
  std::vector<double> dropletsPerParticle;  ///< per parcel
  double duration = 0.0;                    ///< [s]
  double dt = 0.0;                          ///< [s]
  double particlesPerParcel = 1.0;
  double singleDropletCoverage = 0.0;       ///< f of Eq. (15)
};

/// The reference coverage of a database file; nullopt when it has none. rcfd::InputError naming the
/// file and dataset when it is malformed (empty, negative or non-finite values, attributes missing or
/// not positive).
std::optional<ReferenceCoverageData> readReferenceCoverage(const std::string& databasePath);

/// One side's distribution of coverage phi (Eq. (15)) over its members.
struct CoverageSummary {
  double members = 0.0;
  double particlesPerMember = 0.0;
  double dropletsPerParticleMean = 0.0;
  double mean = 0.0, median = 0.0, p10 = 0.0, p90 = 0.0;
};
CoverageSummary summariseCoverage(const std::vector<double>& dropletsPerParticle, double particlesPerMember, double f);

struct CoverageComparison {
  double runDuration = 0.0, referenceDuration = 0.0;
  /// Whether the run covers the reference's duration (within half of the coarser step).
  bool sameDuration = false;
  CoverageSummary run, reference;
  double ksDistance = 0.0;  ///< between the two distributions of phi
  /// (run - reference) / reference; NaN where the reference value is 0.
  double relativeError(double runValue, double referenceValue) const;
  nlohmann::json toJson() const;
};

/// The run's droplets per real particle per tracer against the reference. Throws rcfd::InputError when
/// the reference was sprayed with droplets of another f (another spray, not comparable at all).
CoverageComparison compareCoverage(const std::vector<double>& runDropletsPerParticle, double particlesPerTracer,
                                   double runDuration, double runDt, double f, const ReferenceCoverageData& reference);

}  // namespace rcfd::analysis
