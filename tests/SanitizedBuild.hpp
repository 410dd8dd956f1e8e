#pragma once
/// \file SanitizedBuild.hpp
/// Whether the test program is a sanitizer build (CMakePresets.json asan, tsan: RCFD_SANITIZED). The
/// throughput and wall-clock assertions of the suite hold for the optimised build; a sanitizer build
/// runs 2-20 x slower, so they are not asserted there (everything else is).
namespace rcfd::test {
#ifdef RCFD_SANITIZED
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif
}  // namespace rcfd::test
