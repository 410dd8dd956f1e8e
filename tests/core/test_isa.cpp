// The kernel variant a process runs (core/Isa.hpp): the best one this CPU runs, or the one RCFD_ISA
// names, which must be built and run here.
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "core/Errors.hpp"
#include "core/Isa.hpp"
#include "../ScopedVariable.hpp"

namespace rcfd {
using test::ScopedVariable;

TEST(Isa, TheKernelsRunTheBestBuiltVariantThisCpuRuns) {
  const ScopedVariable unset("RCFD_ISA", std::nullopt);
  const auto built = builtIsas();
  ASSERT_FALSE(built.empty());
#if defined(RCFD_NATIVE_BUILD)
  EXPECT_EQ(built, std::vector<Isa>{Isa::native});
#else
  EXPECT_EQ(built, (std::vector<Isa>{Isa::avx512, Isa::avx2}));
  EXPECT_TRUE(cpuRuns(Isa::avx2)) << "the portable build's baseline: this process would not have started";
#endif
  const Isa picked = kernelIsa();
  EXPECT_TRUE(cpuRuns(picked));
  for (Isa isa : built) {  // nothing better was left out
    if (isa == picked) break;
    EXPECT_FALSE(cpuRuns(isa)) << isaName(isa) << " is built and runs here, but " << isaName(picked) << " was picked";
  }
}

TEST(Isa, RcfdIsaPicksABuiltVariantAndRefusesOthersNamingTheVariable) {
  for (Isa isa : builtIsas()) {
    const ScopedVariable set("RCFD_ISA", isaName(isa));
    if (cpuRuns(isa)) {
      EXPECT_EQ(kernelIsa(), isa);
    } else {  // e.g. avx512 on an AVX2 CPU (tests/portable runs this under an emulated one)
      try {
        kernelIsa();
        ADD_FAILURE() << isaName(isa) << " was accepted on a CPU that does not run it";
      } catch (const InputError& e) {
        ASSERT_EQ(e.violations().size(), 1u);
        EXPECT_EQ(e.violations()[0].pointer, "RCFD_ISA");
        EXPECT_NE(e.violations()[0].message.find("does not run"), std::string::npos) << e.violations()[0].message;
      }
    }
  }
  const ScopedVariable set("RCFD_ISA", "sse2");
  try {
    kernelIsa();
    ADD_FAILURE() << "sse2 was accepted";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u);
    EXPECT_EQ(e.violations()[0].pointer, "RCFD_ISA");
    const std::string& message = e.violations()[0].message;
    for (Isa isa : builtIsas()) {
      EXPECT_NE(message.find(std::string("\"") + isaName(isa) + "\""), std::string::npos) << message;
    }
  }
}

}  // namespace rcfd
