// The paper's recurrence path ("Recurrent processes"): consecutive frames in sequences whose length is
// uniform in [N min_sequence_fraction, N max_sequence_fraction]; at the end of a sequence the path jumps
// to the state most similar to the current one (largest R) in the other half of the database and
// continues at the frame after it. A sequence that reaches the last frame ends there (forced jump),
// so the path never runs past the database.

#include <algorithm>
#include <cmath>
#include <random>

#include "recurrence/PathRandom.hpp"
#include "recurrence/PathSupport.hpp"
#include "recurrence/RecurrencePath.hpp"
#include "recurrence/SequenceWalk.hpp"

namespace rcfd {
namespace {

class PaperPathGenerator final : public PathGenerator {
 public:
  explicit PaperPathGenerator(const PathSpec& spec) : spec_(spec) { checkSequenceFractions(spec_); }

  RecurrencePath generate(const Eigen::MatrixXf& R, std::int64_t steps, std::uint64_t seed) const override {
    checkPathRecurrence(R);
    checkSteps(steps);
    const int n = int(R.rows());
    const int half = n / 2;  // first half [0, half), second half [half, n)
    const std::int64_t shortest = std::max<std::int64_t>(1, std::llround(n * spec_.min_sequence_fraction));
    const std::int64_t longest = std::max(shortest, std::int64_t(std::llround(n * spec_.max_sequence_fraction)));

    // The jump target of every frame, computed once: argmax of R(e, j) over the other half with
    // j <= n - 2 so that the frame after it exists (the first maximum on ties).
    std::vector<int> next(static_cast<std::size_t>(n));
    for (int e = 0; e < n; ++e) {
      const int lo = e < half ? half : 0;
      const int hi = e < half ? n - 2 : half - 1;
      int best = lo;
      for (int j = lo + 1; j <= hi; ++j)
        if (R(e, j) > R(e, best)) best = j;
      next[std::size_t(e)] = best + 1;
    }

    std::mt19937_64 rng(seed);
    return walkSequences(
        n, steps, rng, [&](int e) { return next[std::size_t(e)]; },
        [&] { return path_random::uniformInt(rng, shortest, longest); });
  }

 private:
  PathSpec spec_;
};

const bool registered = PathGeneratorRegistry::add(
    "paper",
    "sequences of uniform random length in [N min_sequence_fraction, N max_sequence_fraction]; jump to "
    "the most similar state in the other half, continue at the frame after it",
    [](const PathSpec& spec) { return std::make_unique<PaperPathGenerator>(spec); });

}  // namespace
}  // namespace rcfd
