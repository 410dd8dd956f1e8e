#include "analysis/ReferenceStatistics.hpp"

#include <cmath>

#include "core/Errors.hpp"
#include "core/Hdf5.hpp"

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

ReferenceStatistics readReferenceStatistics(const std::string& path) {
  namespace L = reference_layout;
  ReferenceStatistics r;
  h5::File f(path, h5::File::Mode::ReadOnly);
  if (f.exists(L::durations)) {
    r.durations = readNonNegative(f, path, L::durations);
    // Optional attributes: absent ones stay 0 (unknown); present ones must be finite and > 0.
    auto optionalAttribute = [&](const char* name) {
      if (!f.hasAttribute(L::durations, name)) return 0.0;
      const double v = f.doubleAttribute(L::durations, name);
      if (!std::isfinite(v) || !(v > 0.0)) {
        throw InputError(path, std::string(L::durations) + "@" + name, std::to_string(v) + "; must be > 0");
      }
      return v;
    };
    r.durationsDt = optionalAttribute("dt");
    r.members = optionalAttribute(L::members);
    r.period = optionalAttribute(L::period);
  } else {
    r.missing.push_back(L::durations);
  }
  if (f.exists(L::holdup)) {
    r.holdup = readNonNegative(f, path, L::holdup);
    const std::string where = std::string(L::holdup) + "@" + L::holdupDt;
    try {
      r.holdupDt = f.doubleAttribute(L::holdup, L::holdupDt);
    } catch (const RunError&) {
      throw InputError(path, where, "attribute missing: the sampling interval of the holdup series [s]");
    }
    if (!std::isfinite(r.holdupDt) || !(r.holdupDt > 0.0)) {
      throw InputError(path, where, std::to_string(r.holdupDt) + " s; must be > 0");
    }
  } else {
    r.missing.push_back(L::holdup);
  }
  return r;
}

}  // namespace rcfd::analysis
