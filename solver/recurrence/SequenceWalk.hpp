#pragma once
/// \file SequenceWalk.hpp
/// The walk shared by the seeded path generators ("paper", "markov"): sequences of consecutive frames
/// joined by jumps. The generators differ only in how a sequence's length and a jump's target are
/// chosen, which they pass in.

#include <cstdint>
#include <random>

#include "recurrence/PathRandom.hpp"
#include "recurrence/RecurrencePath.hpp"

namespace rcfd {

/// `steps` frames of a database of `frames` (>= 3) frames. The path starts at a frame drawn uniformly
/// from [0, frames - 2] and plays consecutive frames for drawLength() steps; then it continues at
/// jumpFrom(e), e the frame it ended on, for a new sequence. A sequence that reaches the last frame
/// ends there (a forced jump), so the path never runs past the database; jumpFrom must return a frame
/// in [0, frames - 1]. Both callables may draw from `rng`: the draws come in a fixed order (start,
/// first length, then per jump the target before the length), so the same seed gives the same path.
template <class JumpFrom, class DrawLength>
RecurrencePath walkSequences(int frames, std::int64_t steps, std::mt19937_64& rng, JumpFrom&& jumpFrom,
                             DrawLength&& drawLength) {
  RecurrencePath path;
  path.frames.resize(std::size_t(steps));
  if (steps == 0) return path;
  int current = int(path_random::uniformInt(rng, 0, frames - 2));
  std::int64_t remaining = drawLength();
  for (std::int64_t s = 0; s < steps; ++s) {
    path.frames[std::size_t(s)] = current;
    --remaining;
    if (remaining <= 0 || current == frames - 1) {
      current = jumpFrom(current);
      remaining = drawLength();
    } else {
      ++current;
    }
  }
  return path;
}

}  // namespace rcfd
