#include "jobs/DatabaseProgress.hpp"

#include <algorithm>
#include <cmath>

namespace rcfd {

DatabaseProgress::DatabaseProgress(const DatabaseSchedule& plan, double settleTime, long parcels, long fallSteps,
                                   std::int64_t cells, bool gas)
    : end_(std::max<std::int64_t>(0, plan.endOffset())) {
  const double n = double(std::max(0L, parcels));
  fill_ = 1.5 * n * double(std::max(0L, fallSteps));
  settle_ = n * std::ceil(std::max(0.0, settleTime) / plan.dtDem);
  perStep_ = n + (gas ? kCoupledCostPerCell * double(cells) : 0.0);
  total_ = fill_ + settle_ + perStep_ * double(end_);
  if (!(total_ > 0.0)) {  // nothing to weigh: count the coupled steps alone
    fill_ = settle_ = 0.0;
    perStep_ = 1.0;
    total_ = std::max<double>(1.0, double(end_));
  }
}

double DatabaseProgress::fill(double stageFraction) const {
  return std::clamp(stageFraction, 0.0, 1.0) * fill_ / total_;
}

double DatabaseProgress::settle(double stageFraction) const {
  return (fill_ + std::clamp(stageFraction, 0.0, 1.0) * settle_) / total_;
}

double DatabaseProgress::coupled(std::int64_t offset) const {
  const double steps = double(std::clamp<std::int64_t>(offset, 0, end_));
  return std::min(1.0, (fill_ + settle_ + steps * perStep_) / total_);
}

const char* coupledPhase(const DatabaseSchedule& plan, std::int64_t offset) {
  if (offset < plan.rampSteps) return "ramp";
  if (offset < plan.frameOffset(0)) return "warmup";
  if (offset < plan.frameOffset(plan.frames)) return "sample";
  return "reference";
}

double coupledPhaseFraction(const DatabaseSchedule& plan, std::int64_t offset) {
  auto between = [&](std::int64_t from, std::int64_t to) {
    return to > from ? std::clamp(double(offset - from) / double(to - from), 0.0, 1.0) : 1.0;
  };
  const std::int64_t end = plan.endOffset();
  const std::int64_t sampled = std::min(plan.frameOffset(plan.frames), end);
  if (offset < plan.rampSteps) return between(0, plan.rampSteps);
  if (offset < plan.frameOffset(0)) return between(plan.rampSteps, plan.frameOffset(0));
  if (offset < plan.frameOffset(plan.frames)) return between(plan.frameOffset(0), sampled);
  return between(plan.frameOffset(plan.frames), end);
}

}  // namespace rcfd
