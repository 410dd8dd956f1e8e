// The start-up check of a portable build: every object but the hot kernels' x86-64-v4 variants is
// compiled for x86-64-v3 (core/Isa.hpp), so on an older CPU the first AVX2 instruction would end the
// process with SIGILL somewhere. This file alone is compiled for plain x86-64 (solver/CMakeLists.txt),
// and its constructor runs before every C++ static initialiser of the program (priority 101), so such a
// CPU gets a message and exit code 3 instead.
#if !defined(RCFD_NATIVE_BUILD) && defined(__x86_64__)
#include <unistd.h>

#include <cstring>

namespace {

__attribute__((constructor(101))) void refuseCpusBelowTheBaseline() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("x86-64-v3")) return;
  const char* message =
      "rcfd: this CPU lacks x86-64-v3 (AVX2, FMA, BMI2, F16C, MOVBE), the instruction set this portable build "
      "was compiled for; build rcfd on this machine with -DRCFD_NATIVE=ON (docs/performance.md, \"Portable "
      "and native builds\")\n";
  [[maybe_unused]] const auto written = ::write(2, message, std::strlen(message));
  ::_exit(3);
}

}  // namespace
#endif
