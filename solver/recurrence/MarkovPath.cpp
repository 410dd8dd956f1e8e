// A Markov variant of the recurrence path: sequence lengths are min_sequence_frames plus a geometric
// number of further frames, with mean length N (min_sequence_fraction + max_sequence_fraction) / 2
// (never below min_sequence_frames); a jump from frame e lands on j + 1 with j drawn with probability
// proportional to R(e, j) among the frames j <= N - 2 with |j - e| > correlation_window (uniformly if
// every such R is 0). Unlike the paper's rule, jump targets are random, so long paths do not cycle
// through the same few transitions.

#include <algorithm>
#include <random>

#include "recurrence/PathRandom.hpp"
#include "recurrence/PathSupport.hpp"
#include "recurrence/RecurrencePath.hpp"
#include "recurrence/SequenceWalk.hpp"

namespace rcfd {
namespace {

class MarkovPathGenerator final : public PathGenerator {
 public:
  explicit MarkovPathGenerator(const PathSpec& spec) : spec_(spec) {
    checkSequenceFractions(spec_);
    if (spec_.min_sequence_frames < 1) {
      throw InputError("scene", "/rcfd/path/min_sequence_frames",
                       std::to_string(spec_.min_sequence_frames) + " must be >= 1");
    }
    if (spec_.correlation_window < 0) {
      throw InputError("scene", "/rcfd/path/correlation_window",
                       std::to_string(spec_.correlation_window) + " must be >= 0");
    }
  }

  RecurrencePath generate(const Eigen::MatrixXf& R, std::int64_t steps, std::uint64_t seed) const override {
    checkPathRecurrence(R);
    checkSteps(steps);
    const int n = int(R.rows());
    const int window = spec_.correlation_window;
    // Every frame needs a jump target j <= n - 2 with |j - e| > window; check up front so a bad
    // window fails the same way whatever the seed.
    for (int e = 0; e < n; ++e) {
      if (e - window - 1 < 0 && e + window + 1 > n - 2) {
        throw InputError("scene", "/rcfd/path/correlation_window",
                         std::to_string(window) + " frames leaves frame " + std::to_string(e) +
                             " no jump target in a database of " + std::to_string(n) + " frames; at most " +
                             std::to_string(std::max(0, (n - 3) / 2)) + " frames allowed here");
      }
    }
    const double meanLength = n * 0.5 * (spec_.min_sequence_fraction + spec_.max_sequence_fraction);
    const double extraMean = std::max(0.0, meanLength - spec_.min_sequence_frames);
    // Geometric number of extra frames: continue with probability q = m / (1 + m) (mean m).
    const std::uint64_t carryOn = path_random::bernoulliThreshold(extraMean / (1.0 + extraMean));

    std::mt19937_64 rng(seed);
    auto drawLength = [&] {
      std::int64_t length = spec_.min_sequence_frames;
      while (rng() < carryOn) ++length;
      return length;
    };
    std::vector<double> cumulative(static_cast<std::size_t>(n));
    auto jumpFrom = [&](int e) {
      double total = 0.0;
      int candidates = 0;
      for (int j = 0; j <= n - 2; ++j) {
        const bool allowed = std::abs(j - e) > window;
        if (allowed) {
          total += std::max(0.0f, R(e, j));
          ++candidates;
        }
        cumulative[std::size_t(j)] = total;
      }
      if (total <= 0.0) {  // no similarity anywhere: uniform over the allowed frames
        std::int64_t k = path_random::uniformInt(rng, 0, candidates - 1);
        for (int j = 0; j <= n - 2; ++j)
          if (std::abs(j - e) > window && k-- == 0) return j + 1;
      }
      const double u = path_random::uniform01(rng) * total;
      for (int j = 0; j <= n - 2; ++j)
        if (std::abs(j - e) > window && cumulative[std::size_t(j)] > u) return j + 1;
      for (int j = n - 2; j >= 0; --j)  // u rounded up to the total: the last allowed frame
        if (std::abs(j - e) > window) return j + 1;
      return 1;
    };

    return walkSequences(n, steps, rng, jumpFrom, drawLength);
  }

 private:
  PathSpec spec_;
};

const bool registered = PathGeneratorRegistry::add(
    "markov",
    "geometric sequence lengths (mean N (min+max fraction)/2, at least min_sequence_frames); jump target "
    "drawn with probability proportional to R outside +-correlation_window",
    [](const PathSpec& spec) { return std::make_unique<MarkovPathGenerator>(spec); });

}  // namespace
}  // namespace rcfd
