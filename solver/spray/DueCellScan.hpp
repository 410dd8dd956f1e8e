#pragma once
/// \file DueCellScan.hpp
/// The deposition's search for the tracers of the cells with droplets due (DepositionEffect.cpp): a pass
/// over every tracer's cell each step, compiled once per kernel variant (core/Isa.hpp, DueCellScan.cpp).

#include <cstdint>
#include <vector>

#include "core/Isa.hpp"

namespace rcfd::spray {

/// Whether cell `cell`'s bit is set in the bitmap `bits` (bit c % 32 of word c / 32).
inline std::uint32_t dueBit(const std::uint32_t* bits, std::int32_t cell) {
  return (bits[cell >> 5] >> (cell & 31)) & 1u;
}

/// Appends to `found`, in order, the tracers first <= i < last whose cell cellOf[i] has its bit set in
/// `dueBits`.
using DueCellScan = void (*)(const std::uint32_t* dueBits, const std::int32_t* cellOf, std::int64_t first,
                             std::int64_t last, std::vector<std::int32_t>& found);

// The variants; a build defines those builtIsas() lists.
namespace isa_avx2 {
void tracersInDueCells(const std::uint32_t* dueBits, const std::int32_t* cellOf, std::int64_t first,
                       std::int64_t last, std::vector<std::int32_t>& found);
}
namespace isa_avx512 {
void tracersInDueCells(const std::uint32_t* dueBits, const std::int32_t* cellOf, std::int64_t first,
                       std::int64_t last, std::vector<std::int32_t>& found);
}
namespace isa_native {
void tracersInDueCells(const std::uint32_t* dueBits, const std::int32_t* cellOf, std::int64_t first,
                       std::int64_t last, std::vector<std::int32_t>& found);
}

/// The variant compiled for `isa` (one of builtIsas()).
DueCellScan dueCellScanFor(Isa isa);

}  // namespace rcfd::spray
