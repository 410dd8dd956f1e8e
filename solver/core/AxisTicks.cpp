#include "core/AxisTicks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rcfd {

double niceStep(double raw) {
  if (!(raw > 0.0) || !std::isfinite(raw)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / p;
  // Thresholds at the geometric means of neighbouring steps (sqrt(2), sqrt(10), sqrt(50)), rounded.
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * p;
}

std::vector<double> niceTicks(double lo, double hi, int approxIntervals) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return ticks;
  const double step = niceStep((hi - lo) / double(std::max(1, approxIntervals)));
  // A range whose ends are multiples of the step up to rounding keeps them as ticks.
  const double slack = 1e-6;
  const double first = std::ceil(lo / step - slack), last = std::floor(hi / step + slack);
  for (double k = first; k <= last; k += 1.0) {
    const double v = k * step;
    ticks.push_back(std::abs(v) < slack * step ? 0.0 : v);
  }
  return ticks;
}

double tickStep(const std::vector<double>& ticks) { return ticks.size() < 2 ? 0.0 : ticks[1] - ticks[0]; }

std::string tickLabel(double value, double step) {
  char buf[40];
  const double magnitude = std::abs(step);
  if (magnitude > 0.0 && (magnitude < 1e-4 || magnitude >= 1e6)) {
    std::snprintf(buf, sizeof buf, "%.3g", value);
    return buf;
  }
  int decimals = 0;
  if (magnitude > 0.0) decimals = std::max(0, -int(std::floor(std::log10(magnitude) + 1e-9)));
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

std::string durationLabel(double seconds) {
  char buf[48];
  if (!std::isfinite(seconds)) return "? s";
  if (std::abs(seconds) < 59.5) {
    std::snprintf(buf, sizeof buf, "%.3g s", seconds);
    return buf;
  }
  if (seconds < 3600.0 - 0.5) {
    const long total = std::lround(seconds);
    const long minutes = total / 60, rest = total % 60;
    if (rest == 0) std::snprintf(buf, sizeof buf, "%ld min", minutes);
    else std::snprintf(buf, sizeof buf, "%ld min %ld s", minutes, rest);
    return buf;
  }
  const long totalMinutes = std::lround(seconds / 60.0);
  const long hours = totalMinutes / 60, minutes = totalMinutes % 60;
  if (minutes == 0) std::snprintf(buf, sizeof buf, "%ld h", hours);
  else std::snprintf(buf, sizeof buf, "%ld h %ld min", hours, minutes);
  return buf;
}

}  // namespace rcfd
