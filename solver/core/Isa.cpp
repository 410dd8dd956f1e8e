#include "core/Isa.hpp"

#include <cstdlib>
#include <string_view>

#include "core/Errors.hpp"

namespace rcfd {

const char* isaName(Isa isa) {
  switch (isa) {
    case Isa::avx2: return "avx2";
    case Isa::avx512: return "avx512";
    case Isa::native: return "native";
  }
  return "?";
}

std::vector<Isa> builtIsas() {
#if defined(RCFD_NATIVE_BUILD)
  return {Isa::native};
#else
  return {Isa::avx512, Isa::avx2};
#endif
}

bool cpuRuns(Isa isa) {
  __builtin_cpu_init();
  switch (isa) {
    case Isa::avx2: return __builtin_cpu_supports("x86-64-v3");
    case Isa::avx512: return __builtin_cpu_supports("x86-64-v4");
    case Isa::native: return true;
  }
  return false;
}

Isa kernelIsa() {
  const std::vector<Isa> built = builtIsas();
  const char* asked = std::getenv("RCFD_ISA");
  if (!asked || !*asked) {
    for (Isa isa : built) {
      if (cpuRuns(isa)) return isa;
    }
    return built.back();  // the baseline: the build's start-up check refused CPUs without it
  }
  std::string names;
  for (Isa isa : built) {
    if (std::string_view(asked) == isaName(isa)) {
      if (!cpuRuns(isa)) {
        throw InputError("environment", "RCFD_ISA",
                         std::string("\"") + asked + "\": this CPU does not run the " + asked + " variant");
      }
      return isa;
    }
    names += std::string(names.empty() ? "" : ", ") + "\"" + isaName(isa) + "\"";
  }
  throw InputError("environment", "RCFD_ISA",
                   std::string("\"") + asked + "\" is not a kernel variant of this build; allowed: " + names);
}

}  // namespace rcfd
