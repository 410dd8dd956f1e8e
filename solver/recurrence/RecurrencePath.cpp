#include "recurrence/RecurrencePath.hpp"

#include <stdexcept>

namespace rcfd {

std::int64_t RecurrencePath::jumpCount() const {
  std::int64_t jumps = 0;
  for (std::int64_t s = 1; s < std::int64_t(frames.size()); ++s) jumps += isJump(s) ? 1 : 0;
  return jumps;
}

PathStatistics pathStatistics(const RecurrencePath& path, const Eigen::MatrixXf& recurrence) {
  PathStatistics st;
  const int n = int(recurrence.rows());
  double similarity = 0.0;
  for (std::size_t s = 0; s < path.frames.size(); ++s) {
    if (path.frames[s] < 0 || path.frames[s] >= n) {
      throw std::out_of_range("path step " + std::to_string(s) + " uses frame " +
                              std::to_string(path.frames[s]) + " of " + std::to_string(n));
    }
    if (!path.isJump(std::int64_t(s))) continue;
    ++st.jumps;
    // The state left (frames[s-1]) against the state the jump matched: the predecessor of the frame
    // landed on, since a jump continues at the frame after the most similar state.
    const int from = path.frames[s - 1];
    const int matched = path.frames[s] > 0 ? path.frames[s] - 1 : 0;
    similarity += recurrence(from, matched);
  }
  st.meanJumpSimilarity = st.jumps > 0 ? similarity / double(st.jumps) : 0.0;
  st.meanSequenceLength = double(path.frames.size()) / double(st.jumps + 1);
  return st;
}

}  // namespace rcfd
