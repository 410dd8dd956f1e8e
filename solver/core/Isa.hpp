#pragma once
/// \file Isa.hpp
/// The instruction sets the hot kernels are compiled for, and which of them this CPU runs.
///
/// A portable build (the default) compiles rcfd for x86-64-v3 (AVX2, FMA, BMI2, F16C, MOVBE: every
/// x86-64 server CPU since 2015) and its hot kernels a second time for x86-64-v4 (AVX-512 F, BW, CD, DQ,
/// VL); each kernel call runs the best variant this CPU runs (kernelIsa()). A native build
/// (`-DRCFD_NATIVE=ON`) compiles everything for the build machine's CPU: one variant, `native`.
/// How a kernel gets variants: docs/architecture.md, "Hot kernels and instruction sets".

#include <string>
#include <vector>

namespace rcfd {

enum class Isa {
  avx2,    ///< x86-64-v3, the portable build's baseline
  avx512,  ///< x86-64-v4
  native,  ///< the build machine's CPU (`-DRCFD_NATIVE=ON`)
};

/// "avx2", "avx512" or "native"
const char* isaName(Isa isa);

/// The kernel variants compiled into this build, best first.
std::vector<Isa> builtIsas();

/// Whether this CPU runs code compiled for `isa` (`native`: always, as the build refuses to start on a
/// CPU without the baseline).
bool cpuRuns(Isa isa);

/// The variant the hot kernels run: the one the environment variable RCFD_ISA names ("avx2", "avx512"
/// or "native"), for comparing variants on one machine, else the best built one this CPU runs. Throws
/// InputError (pointer "RCFD_ISA") for a name not built or a variant this CPU does not run.
Isa kernelIsa();

}  // namespace rcfd
