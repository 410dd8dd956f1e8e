#include "jobs/EtaEstimator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rcfd {

void EtaEstimator::restart(double t, double fraction) {
  samples_.clear();
  samples_.emplace_back(t, fraction);
  start_ = t;
  last_ = -1.0;
  lastTime_ = t;
  raw_ = -1.0;
}

void EtaEstimator::skip(double seconds) {
  if (!(seconds > 0.0)) return;
  for (auto& sample : samples_) sample.first += seconds;
  start_ += seconds;
  lastTime_ += seconds;
}

double EtaEstimator::update(double t, double fraction) {
  if (fraction < samples_.back().second) restart(t, fraction);
  if (fraction >= 1.0) {
    samples_.emplace_back(t, fraction);
    raw_ = last_ = 0.0;
    lastTime_ = t;
    return 0.0;
  }
  // A stall adds no information beyond its length: keep one sample for it, at its latest time.
  if (samples_.size() >= 2 && samples_.back().second == fraction && samples_[samples_.size() - 2].second == fraction) {
    samples_.back().first = t;
  } else {
    samples_.emplace_back(t, fraction);
  }
  // The window ends now and starts `window` before the last progress (during a stall the rate then
  // falls as the stall lengthens); keep the newest sample at or before its start, so the rate spans it.
  const std::size_t n = samples_.size();
  const double lastProgress = n >= 2 && samples_[n - 2].second == fraction ? samples_[n - 2].first : t;
  while (samples_.size() > 2 && samples_[1].first <= lastProgress - s_.window) samples_.pop_front();
  const auto& [t0, f0] = samples_.front();
  const double rate = t > t0 ? (fraction - f0) / (t - t0) : 0.0;
  const bool known = rate > 0.0 && t - start_ >= s_.minSpan;
  raw_ = known ? (1.0 - fraction) / rate : -1.0;

  if (t - start_ < s_.settle || last_ < 0.0) {
    // Settling, or the first estimate since: report the raw one, from which the limit starts.
    last_ = raw_;
    lastTime_ = t;
    return last_;
  }
  const double dt = std::max(0.0, t - lastTime_);
  const double growth = std::exp2(dt / s_.window);
  // Downwards from the previous estimate counted down (a job on time counts down freely); upwards
  // from the previous estimate itself, so that a short estimate can still grow (counted down, one
  // below 86 s would shrink faster than a factor 2 per minute lets it grow).
  const double lo = std::max(0.0, last_ - dt) / growth;
  const double hi = std::max(last_, s_.floor) * growth;
  const double target = known ? raw_ : std::numeric_limits<double>::infinity();
  last_ = std::clamp(target, lo, hi);
  lastTime_ = t;
  return last_;
}

}  // namespace rcfd
