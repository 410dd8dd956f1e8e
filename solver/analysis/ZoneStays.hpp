#pragma once
/// \file ZoneStays.hpp
/// Stays of numbered members (rCFD tracers by index, DEM parcels by their permanent id) in a zone such
/// as the spray zone, observed at whole sample counts: a member seen inside at sample e and first seen
/// outside again at sample s stayed s - e samples. Durations are integers, so histograms and sums are
/// identical for any thread count and across checkpoint/resume; the true duration of a stay is within
/// one sample of the count. Stays already open at the first observation (entry unknown), or that
/// began before `countFrom`, and stays still open at the end are not counted (the latter are reported
/// as censored). Shared by the tracer effect `residence_time` and the database job's reference RTD.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/Permutation.hpp"

namespace rcfd {

namespace h5 {
class File;
}

/// Residence-time statistics of the completed stays.
struct StayStatistics {
  std::int64_t stays = 0;      ///< completed stays counted
  std::int64_t censored = 0;   ///< stays still open at the end
  double mean_s = 0.0;         ///< mean duration [s] (0 without stays)
  double median_s = 0.0;       ///< median duration [s] (0 without stays)
  double p90_s = 0.0;          ///< 90th percentile of the durations [s] (0 without stays)
  std::vector<double> edges;   ///< histogram bin edges [s], bins + 1 of them from 0
  std::vector<std::int64_t> counts;  ///< stays per bin

  /// {"mean_s", "median_s", "p90_s", "stays", "censored", "histogram": {"edges", "counts"}}
  /// (docs/contracts.md, "summary.json").
  nlohmann::json toJson() const;
};

class ZoneStays {
 public:
  static constexpr std::int64_t kOutside = -1;
  static constexpr std::int64_t kUnknownEntry = -2;  ///< inside at the start: the entry is unknown

  explicit ZoneStays(std::size_t members = 0) : entry_(members, kOutside) {}

  std::size_t members() const { return entry_.size(); }
  /// Whether member i is inside now (its stay is open): observe() changes nothing unless `inside`
  /// differs from this, which lets callers skip the members that neither entered nor left.
  bool isInside(std::size_t i) const { return entry_[i] != kOutside; }
  /// entry_ as an array, for loops that test isInside() for many members at once.
  const std::int64_t* entries() const { return entry_.data(); }

  /// Member i is inside at the start: its stay has no known entry and is never counted.
  void startInside(std::size_t i) { entry_[i] = kUnknownEntry; }

  /// Member i observed at sample `step` (inside or not). Returns the duration in samples of the stay
  /// that ends now (first sample outside) if it began at or after countFrom, else -1. Safe to call
  /// concurrently for different members; record returned durations with addDurations().
  std::int64_t observe(std::size_t i, bool inside, std::int64_t step, std::int64_t countFrom) {
    std::int64_t& e = entry_[i];
    if (inside) {
      if (e == kOutside) e = step;
      return -1;
    }
    std::int64_t finished = -1;
    if (e != kOutside && e >= countFrom) finished = step - e;
    e = kOutside;
    return finished;
  }

  /// The members were reordered: member j is the one that was member from[j].
  void permute(const std::vector<std::int32_t>& from) { applyPermutation(entry_, from); }

  /// Adds completed stays (durations in samples) to the histogram of durations.
  void addDurations(const std::vector<std::int64_t>& durations);

  /// Completed stays per duration in samples (index = duration).
  const std::vector<std::int64_t>& durationCounts() const { return durationCounts_; }
  /// Every completed stay's duration [s], in increasing order (dt: seconds per sample).
  std::vector<double> durations(double dt) const;
  /// Members inside now (open stays, counted or not).
  std::int64_t open() const;

  /// Mean, median and a histogram of `bins` equal bins from 0 to the longest stay (at least one
  /// sample) [s].
  StayStatistics statistics(double dt, int bins) const;

  void save(h5::File& file, const std::string& group) const;
  void load(const h5::File& file, const std::string& group);

 private:
  std::vector<std::int64_t> entry_;           ///< sample a member entered, or kOutside / kUnknownEntry
  std::vector<std::int64_t> durationCounts_;  ///< stays per duration in samples
};

}  // namespace rcfd
