#include "analysis/ReferenceStatistics.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "analysis/StayComparison.hpp"

namespace rcfd::analysis {
namespace {

std::vector<double> readNonNegative(const h5::File& f, const std::string& path, const std::string& name) {
  auto v = f.readDoubles(name);
  if (v.empty()) throw InputError(path, name, "is empty; store at least one value or leave the dataset out");
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i]) || v[i] < 0.0) {
      throw InputError(path, name, "entry " + std::to_string(i) + " is " + std::to_string(v[i]) +
                                       "; values must be finite and >= 0");
    }
  }
  return v;
}

/// The spray zone of a scene document, its keys' defaults where absent; nullopt without a `/spray/spray_zone`.
std::optional<SprayZoneSpec> sprayZoneOf(const std::string& sceneJson) {
  const auto doc = nlohmann::json::parse(sceneJson, nullptr, false);
  const auto pointer = nlohmann::json::json_pointer("/spray/spray_zone");
  if (doc.is_discarded() || !doc.is_object() || !doc.contains(pointer) || !doc.at(pointer).is_object()) return std::nullopt;
  const auto& z = doc.at(pointer);
  SprayZoneSpec spec;
  try {
    if (z.contains("apex")) spec.apex = Vec3(z["apex"].at(0).get<double>(), z["apex"].at(1).get<double>(), z["apex"].at(2).get<double>());
    spec.half_angle_deg = z.value("half_angle_deg", spec.half_angle_deg);
    spec.y_min = z.value("y_min", spec.y_min);
    spec.y_max = z.value("y_max", spec.y_max);
    spec.line_of_sight = z.value("line_of_sight", spec.line_of_sight);
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
  return spec;
}

std::string describe(const SprayZoneSpec& z) {
  std::ostringstream s;
  s.precision(6);
  s << "apex (" << z.apex.x() << ", " << z.apex.y() << ", " << z.apex.z() << ") m, half-angle " << z.half_angle_deg
    << " deg, y " << z.y_min << "-" << z.y_max << " m" << (z.line_of_sight ? ", line of sight" : "");
  return s.str();
}

bool sameZone(const SprayZoneSpec& a, const SprayZoneSpec& b) {
  auto near = [](double x, double y) { return std::abs(x - y) <= 1e-12 * std::max({1.0, std::abs(x), std::abs(y)}); };
  return near(a.apex.x(), b.apex.x()) && near(a.apex.y(), b.apex.y()) && near(a.apex.z(), b.apex.z()) &&
         near(a.half_angle_deg, b.half_angle_deg) && near(a.y_min, b.y_min) && near(a.y_max, b.y_max) &&
         a.line_of_sight == b.line_of_sight;
}

/// Reads one period's stays and holdup into r (absent datasets into r.missing).
void readPeriod(const h5::File& f, const std::string& path, const char* durations, const char* holdup,
                ReferenceStatistics& r) {
  namespace L = reference_layout;
  if (f.exists(durations)) {
    r.durations = readNonNegative(f, path, durations);
    // Optional attributes: absent ones stay 0 (unknown); present ones must be finite and > 0.
    auto optionalAttribute = [&](const char* name) {
      if (!f.hasAttribute(durations, name)) return 0.0;
      const double v = f.doubleAttribute(durations, name);
      if (!std::isfinite(v) || !(v > 0.0)) {
        throw InputError(path, std::string(durations) + "@" + name, std::to_string(v) + "; must be > 0");
      }
      return v;
    };
    r.durationsDt = optionalAttribute("dt");
    r.members = optionalAttribute(L::members);
    r.period = optionalAttribute(L::period);
  } else {
    r.missing.push_back(durations);
  }
  if (f.exists(holdup)) {
    r.holdup = readNonNegative(f, path, holdup);
    const std::string where = std::string(holdup) + "@" + L::holdupDt;
    try {
      r.holdupDt = f.doubleAttribute(holdup, L::holdupDt);
    } catch (const RunError&) {
      throw InputError(path, where, "attribute missing: the sampling interval of the holdup series [s]");
    }
    if (!std::isfinite(r.holdupDt) || !(r.holdupDt > 0.0)) {
      throw InputError(path, where, std::to_string(r.holdupDt) + " s; must be > 0");
    }
  } else {
    r.missing.push_back(holdup);
  }
}

}  // namespace

double ReferenceStatistics::holdupMean() const {
  double sum = 0.0;
  for (const double h : holdup) sum += h;
  return holdup.empty() ? 0.0 : sum / double(holdup.size());
}

double referenceMembers(const ReferenceStatistics& reference, double bedMass, double particleDensity,
                        double particleDiameter) {
  if (reference.members > 0.0) return reference.members;
  const double particleMass = particleDensity * 3.14159265358979323846 / 6.0 * std::pow(particleDiameter, 3);
  return bedMass / particleMass;
}

nlohmann::json compareWithPeriod(const ReferenceStatistics& period, const std::vector<std::int64_t>& stepCounts,
                                 double dt, double tracers, double runPeriod, double runHoldupMean,
                                 double fallbackMembers) {
  auto numberOrNull = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json out = {{"period_s", period.recordedPeriod()},
                        {"holdup_relative_error", nullptr},
                        {"mean_relative_error", nullptr},
                        {"crossing_rate_relative_error", nullptr}};
  if (period.hasHoldup() && period.holdupMean() > 0.0) {
    out["holdup_mean"] = period.holdupMean();
    out["holdup_relative_error"] = (runHoldupMean - period.holdupMean()) / period.holdupMean();
  }
  if (period.hasDurations()) {
    const double members = period.members > 0.0 ? period.members : fallbackMembers;
    const StayComparison c =
        compareStays(stepCounts, dt, tracers, runPeriod, period.durations, members, period.recordedPeriod());
    out["ks_distance"] = c.ksDistance;
    out["mean_relative_error"] = numberOrNull(c.meanError());
    out["crossing_rate_relative_error"] = numberOrNull(c.crossingRateError());
  }
  return out;
}

ReferenceStatistics readReferenceStatistics(const std::string& path, const SprayZoneSpec* zone) {
  namespace L = reference_layout;
  ReferenceStatistics r;
  h5::File f(path, h5::File::Mode::ReadOnly);
  if (zone && f.exists("/scene") && (f.exists(L::durations) || f.exists(L::holdup))) {
    if (const auto counted = sprayZoneOf(f.readString("/scene")); counted && !sameZone(*counted, *zone)) {
      r.zoneMismatch = "the database's reference was counted in the spray zone " + describe(*counted) +
                       ", the job's is " + describe(*zone) + "; its stays and holdup are not compared";
      r.missing = {L::durations, L::holdup};
      return r;
    }
  }
  readPeriod(f, path, L::durations, L::holdup, r);
  if (f.exists(L::sampledHoldup)) {
    auto sampled = std::make_shared<ReferenceStatistics>();
    readPeriod(f, path, L::sampledDurations, L::sampledHoldup, *sampled);
    r.sampledPeriod = std::move(sampled);
  }
  return r;
}

}  // namespace rcfd::analysis
