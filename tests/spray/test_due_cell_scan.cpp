// The deposition's scan for the tracers of the cells with droplets due (spray/DueCellScan.hpp), in
// every variant this CPU runs, against a plain filter.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "core/Isa.hpp"
#include "spray/DueCellScan.hpp"

namespace rcfd {

TEST(DueCellScan, EveryVariantFindsTheTracersOfTheDueCellsInOrder) {
  std::mt19937_64 rng(41);
  const std::int32_t cells = 70'001;  // not a multiple of 32
  const std::int64_t tracers = 100'003;  // not a multiple of the scan's blocks
  std::vector<std::uint32_t> bits(static_cast<std::size_t>(cells + 31) / 32, 0);
  for (int k = 0; k < 40; ++k) {  // a few due cells, as in a spray step, the last cell among them
    const std::int32_t c = k == 0 ? cells - 1 : std::int32_t(rng() % std::uint64_t(cells));
    bits[std::size_t(c) >> 5] |= std::uint32_t(1) << (c & 31);
  }
  std::vector<std::int32_t> cellOf(static_cast<std::size_t>(tracers));
  for (auto& c : cellOf) c = std::int32_t(rng() % std::uint64_t(cells));
  cellOf[7] = cells - 1;
  for (const auto& [first, last] : std::vector<std::pair<std::int64_t, std::int64_t>>{{0, tracers}, {5, 300}, {1000, 1000}}) {
    std::vector<std::int32_t> expected;
    for (std::int64_t i = first; i < last; ++i) {
      if (spray::dueBit(bits.data(), cellOf[std::size_t(i)])) expected.push_back(std::int32_t(i));
    }
    if (last - first > 1000) EXPECT_GT(expected.size(), 10u);
    int variants = 0;
    for (Isa isa : builtIsas()) {
      if (!cpuRuns(isa)) continue;
      ++variants;
      std::vector<std::int32_t> found{-1};  // appended to, not replaced
      spray::dueCellScanFor(isa)(bits.data(), cellOf.data(), first, last, found);
      ASSERT_EQ(found.size(), expected.size() + 1) << isaName(isa);
      EXPECT_EQ(found.front(), -1);
      EXPECT_EQ(std::vector<std::int32_t>(found.begin() + 1, found.end()), expected) << isaName(isa);
    }
    EXPECT_GE(variants, 1);
  }
}

}  // namespace rcfd
