// The deposition's search for the tracers of the cells with droplets due (DueCellScan.hpp). Compiled
// once per kernel variant (core/Isa.hpp).
#include <algorithm>

#include "core/IsaNamespace.hpp"
#include "spray/DueCellScan.hpp"

namespace rcfd::spray::RCFD_ISA_NAMESPACE {

void tracersInDueCells(const std::uint32_t* dueBits, const std::int32_t* cellOf, std::int64_t first,
                       std::int64_t last, std::vector<std::int32_t>& found) {
  // Blocks of tracers tested against the bitmap (9 KB for 74k cells, in L1, where the slot array is
  // not), in a loop that vectorises (a gather per 16 tracers with AVX-512); the few blocks with a member
  // are then walked tracer by tracer, in order.
  constexpr std::int64_t kScanBlock = 256;
  for (std::int64_t i0 = first; i0 < last; i0 += kScanBlock) {
    const int count = int(std::min(kScanBlock, last - i0));
    const std::int32_t* cells = cellOf + i0;
    std::uint32_t any = 0;
#pragma omp simd reduction(| : any)
    for (int k = 0; k < count; ++k) any |= dueBit(dueBits, cells[k]);
    if (any == 0) continue;
    for (int k = 0; k < count; ++k) {
      if (dueBit(dueBits, cells[k])) found.push_back(std::int32_t(i0 + k));
    }
  }
}

}  // namespace rcfd::spray::RCFD_ISA_NAMESPACE
