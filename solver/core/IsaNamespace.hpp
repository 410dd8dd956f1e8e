#pragma once
/// \file IsaNamespace.hpp
/// RCFD_ISA_NAMESPACE: the namespace that keeps apart the definitions of a kernel compiled once per
/// instruction set (core/Isa.hpp): isa_avx512 in a kernel's x86-64-v4 variant (the build defines
/// RCFD_KERNEL_VARIANT_AVX512 there), isa_native in a native build, else isa_avx2. Inline functions
/// whose code differs by instruction set (an `#if defined(__AVX2__)` inside) are declared in it, as an
/// inline namespace (callers name them as before), so that each variant calls its own.

#if defined(RCFD_KERNEL_VARIANT_AVX512)
#define RCFD_ISA_NAMESPACE isa_avx512
#elif defined(RCFD_NATIVE_BUILD)
#define RCFD_ISA_NAMESPACE isa_native
#else
#define RCFD_ISA_NAMESPACE isa_avx2
#endif
