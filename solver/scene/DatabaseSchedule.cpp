#include "scene/DatabaseSchedule.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/Errors.hpp"

namespace rcfd {
namespace {

/// Relative tolerance for "a whole number": rates and durations given in decimal (200 Hz, 1e-5 s)
/// are not exact in binary, their ratios are whole numbers up to round-off.
constexpr double kWholeTolerance = 1e-9;

std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

/// x rounded if it is a whole number >= minimum, else a violation.
std::int64_t whole(double x, std::int64_t minimum, const std::string& pointer, const std::string& what,
                   std::vector<Violation>& out) {
  const double n = std::round(x);
  if (!std::isfinite(x) || std::abs(x - n) > kWholeTolerance * std::max(1.0, std::abs(x)) || n < double(minimum)) {
    out.push_back({pointer, what + " = " + num(x) + "; must be a whole number >= " + std::to_string(minimum)});
    return minimum;
  }
  return std::int64_t(n);
}

}  // namespace

std::vector<Violation> DatabaseSchedule::violations(const Scene& scene) {
  std::vector<Violation> v;
  schedule(scene, v);
  return v;
}

DatabaseSchedule DatabaseSchedule::fromScene(const Scene& scene) {
  std::vector<Violation> v;
  DatabaseSchedule s = schedule(scene, v);
  if (!v.empty()) throw InputError("scene", std::move(v));
  return s;
}

DatabaseSchedule DatabaseSchedule::schedule(const Scene& scene, std::vector<Violation>& v) {
  const DemSpec& d = scene.dem;
  DatabaseSchedule s;
  s.dtDem = d.time_step;
  s.frameSteps = whole(1.0 / (d.sample_rate * d.time_step), 1, "/dem/sample_rate",
                       "DEM steps per frame 1 / (sample_rate * time_step) = 1 / (" + num(d.sample_rate) + " Hz * " +
                           num(d.time_step) + " s)",
                       v);
  s.sampleSteps = whole(1.0 / (d.probe_rate * d.time_step), 1, "/dem/probe_rate",
                        "DEM steps per reference sample 1 / (probe_rate * time_step) = 1 / (" + num(d.probe_rate) +
                            " Hz * " + num(d.time_step) + " s)",
                        v);
  if (v.empty()) {
    whole(d.probe_rate / d.sample_rate, 1, "/dem/probe_rate",
          "probe_rate / sample_rate = " + num(d.probe_rate) + " / " + num(d.sample_rate), v);
  }
  s.frames = whole(d.sample_duration * d.sample_rate, 3, "/dem/sample_duration",
                   "frames sample_duration * sample_rate = " + num(d.sample_duration) + " s * " + num(d.sample_rate) +
                       " Hz (Eq. (8) needs at least 3)",
                   v);
  s.referenceSamples = whole(d.reference_duration * d.probe_rate, 0, "/dem/reference_duration",
                             "reference samples reference_duration * probe_rate = " + num(d.reference_duration) +
                                 " s * " + num(d.probe_rate) + " Hz",
                             v);
  s.rampSteps = std::llround(d.ramp_time / d.time_step);
  s.warmupSteps = std::llround(d.warmup / d.time_step);
  return s;
}

std::int64_t DatabaseSchedule::endOffset() const {
  return std::max(frameOffset(frames - 1), sampleOffset(totalSamples() - 1));
}

double DatabaseSchedule::flowFactor(std::int64_t offset) const {
  if (rampSteps <= 0 || offset >= rampSteps) return 1.0;
  return offset <= 0 ? 0.0 : double(offset) / double(rampSteps);
}

}  // namespace rcfd
