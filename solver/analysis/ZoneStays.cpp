#include "analysis/ZoneStays.hpp"

#include <algorithm>

#include "core/Hdf5.hpp"

namespace rcfd {

nlohmann::json StayStatistics::toJson() const {
  return {{"mean_s", mean_s},
          {"median_s", median_s},
          {"p90_s", p90_s},
          {"stays", stays},
          {"censored", censored},
          {"histogram", {{"edges", edges}, {"counts", counts}}}};
}

void ZoneStays::addDurations(const std::vector<std::int64_t>& durations) {
  for (const std::int64_t d : durations) {  // integer counts: the order of addition does not matter
    if (std::size_t(d) >= durationCounts_.size()) durationCounts_.resize(std::size_t(d) + 1, 0);
    ++durationCounts_[std::size_t(d)];
  }
}

std::vector<double> ZoneStays::durations(double dt) const {
  std::vector<double> out;
  for (std::size_t d = 0; d < durationCounts_.size(); ++d) {
    out.insert(out.end(), std::size_t(durationCounts_[d]), double(d) * dt);
  }
  return out;
}

std::int64_t ZoneStays::open() const {
  return std::count_if(entry_.begin(), entry_.end(), [](std::int64_t e) { return e != kOutside; });
}

StayStatistics ZoneStays::statistics(double dt, int bins) const {
  StayStatistics s;
  std::int64_t sumSteps = 0;
  for (std::size_t d = 0; d < durationCounts_.size(); ++d) {
    s.stays += durationCounts_[d];
    sumSteps += std::int64_t(d) * durationCounts_[d];
  }
  // Median and p90 from the integer histogram (the lower quantiles, as StayComparison's).
  bool medianFound = false;
  for (std::int64_t d = 0, seen = 0; d < std::int64_t(durationCounts_.size()) && s.stays > 0; ++d) {
    seen += durationCounts_[std::size_t(d)];
    if (!medianFound && 2 * seen >= s.stays) s.median_s = double(d) * dt, medianFound = true;
    if (10 * seen >= 9 * s.stays) {
      s.p90_s = double(d) * dt;
      break;
    }
  }
  s.mean_s = s.stays > 0 ? double(sumSteps) / double(s.stays) * dt : 0.0;
  bins = std::max(1, bins);
  const double maxDuration = std::max(1.0, double(durationCounts_.size())) * dt;
  s.edges.resize(std::size_t(bins) + 1);
  s.counts.assign(std::size_t(bins), 0);
  for (int b = 0; b <= bins; ++b) s.edges[std::size_t(b)] = maxDuration * b / bins;
  for (std::size_t d = 0; d < durationCounts_.size(); ++d) {
    const int b = std::min(bins - 1, int(double(d) * dt / maxDuration * bins));
    s.counts[std::size_t(b)] += durationCounts_[d];
  }
  s.censored = open();
  return s;
}

void ZoneStays::save(h5::File& f, const std::string& g) const {
  f.write(g + "/entry", entry_);
  f.write(g + "/duration_counts", durationCounts_);
}

void ZoneStays::load(const h5::File& f, const std::string& g) {
  entry_ = f.readInt64s(g + "/entry");
  durationCounts_ = f.readInt64s(g + "/duration_counts");
}

}  // namespace rcfd
