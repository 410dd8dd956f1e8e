#pragma once
/// \file BlockPath.hpp
/// The motion kernel's block path (MotionKernel.hpp), the hot loop of a spray run: every tracer of a
/// step moved in blocks of 64 lanes. BlockPath.cpp is compiled once per kernel variant (core/Isa.hpp),
/// each copy in its own namespace; MotionKernel calls the one kernelIsa() picks through
/// moveTracersFor().

#include <functional>

#include "core/Isa.hpp"
#include "tracers/BlockLanes.hpp"
#include "tracers/MotionStatistics.hpp"

namespace rcfd::block {

/// Moves the step's in.tracers tracers: per block startBlock() and moveBlock(), then the threads'
/// deferred lanes; `beside` runs once on the team's last thread (MotionKernel::move()). Adds what the
/// moves did to `stats`.
using MoveTracers = void (*)(const StepInputs& in, const std::function<void()>& beside, MotionStatistics& stats);

// The variants; a build defines those builtIsas() lists.
namespace isa_avx2 {
void moveTracers(const StepInputs& in, const std::function<void()>& beside, MotionStatistics& stats);
}
namespace isa_avx512 {
void moveTracers(const StepInputs& in, const std::function<void()>& beside, MotionStatistics& stats);
}
namespace isa_native {
void moveTracers(const StepInputs& in, const std::function<void()>& beside, MotionStatistics& stats);
}

/// The variant compiled for `isa` (one of builtIsas()).
MoveTracers moveTracersFor(Isa isa);

}  // namespace rcfd::block
