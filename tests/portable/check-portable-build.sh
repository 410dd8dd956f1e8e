#!/usr/bin/env bash
# The portable build's promises (core/Isa.hpp, docs/architecture.md "Hot kernels and instruction sets"):
#   avx512-only-in-its-variant BUILD  no function outside the hot kernels' AVX-512 variant (namespace
#                                     isa_avx512, or a copy renamed *.isa_avx512) uses AVX-512 registers
#   runs-without-avx512 BUILD         on an emulated Haswell (AVX2, no AVX-512; qemu-x86_64) the kernel's
#                                     variants match the reference motion and RCFD_ISA=avx512 is refused
#   refuses-older-cpus BUILD          on an emulated Nehalem (no AVX2) every program says what is missing
#                                     and exits 3 instead of dying of an illegal instruction
# Exit 77 (skipped) where a tool it needs is missing.
set -euo pipefail
mode=$1 build=$2
skip() { echo "skipped: $*"; exit 77; }

case "$mode" in
  avx512-only-in-its-variant)
    command -v objdump > /dev/null || skip "objdump is not installed (binutils)"
    status=0
    for program in rcfd-solve rcfd-server; do
      [ -x "$build/$program" ] || continue
      # Per function: does it touch a zmm register, a mask register, xmm16-31/ymm16-31 (EVEX only) or
      # an embedded broadcast? Prints "name count".
      report=$(objdump -d --no-show-raw-insn -C "$build/$program" | awk '
        /^[0-9a-f]+ <.*>:$/ { name = substr($0, index($0, "<") + 1); sub(/>:$/, "", name); next }
        /%zmm[0-9]|%k[1-7]|%[xy]mm(1[6-9]|2[0-9]|3[01])|\{1to[0-9]+\}/ { uses[name]++ }
        END { for (f in uses) print uses[f] "\t" f }')
      inside=$(printf '%s\n' "$report" | grep -c 'isa_avx512' || true)
      outside=$(printf '%s\n' "$report" | grep . | grep -v 'isa_avx512' || true)
      echo "$program: $inside function(s) of the AVX-512 variant use AVX-512"
      if [ "$inside" -eq 0 ]; then
        echo "FAIL: $program has no AVX-512 code in its AVX-512 variant: is the variant compiled for x86-64-v4?"
        status=1
      fi
      if [ -n "$outside" ]; then
        echo "FAIL: $program uses AVX-512 outside the AVX-512 variant (instructions, function):"
        printf '%s\n' "$outside" | head -20
        status=1
      fi
    done
    exit $status
    ;;
  runs-without-avx512)
    command -v qemu-x86_64 > /dev/null || skip "qemu-x86_64 is not installed (Debian package qemu-user)"
    # The kernel's first 4 random cases (every way of moving; emulation is about 200 x slower) in every
    # variant the emulated CPU runs (AVX2 only), and the refusal of RCFD_ISA=avx512 there. One thread:
    # ctest runs another test on the other core.
    log=$(mktemp)
    trap 'rm -f "$log"' EXIT
    code=0
    OMP_NUM_THREADS=1 RCFD_KERNEL_RANDOM_CASES=4 qemu-x86_64 -cpu Haswell "$build/tests/rcfd-test-tracers" \
      --gtest_filter='Kernel.BlockPathMatchesTheReferenceMotionOnRandomCases' > "$log" 2> /dev/null || code=$?
    grep -E '^(avx|\[  )' "$log" | sed -n '1p;$p'
    if [ "$code" -ne 0 ]; then
      echo "FAIL: the kernel test on an emulated Haswell exited $code:"; tail -30 "$log"; exit 1
    fi
    if grep -q '^avx512' "$log" || ! grep -q '^avx2' "$log"; then
      echo "FAIL: on an AVX2 CPU the kernel test ran other variants than avx2:"; grep -E '^avx' "$log" | head; exit 1
    fi
    qemu-x86_64 -cpu Haswell "$build/tests/rcfd-test-core" --gtest_filter='Isa.*' 2> /dev/null | tail -3
    ;;
  refuses-older-cpus)
    command -v qemu-x86_64 > /dev/null || skip "qemu-x86_64 is not installed (Debian package qemu-user)"
    status=0
    for program in rcfd-solve rcfd-server rcfd rcfd-bench; do
      [ -x "$build/$program" ] || continue
      code=0
      message=$(qemu-x86_64 -cpu Nehalem "$build/$program" --help 2>&1 > /dev/null) || code=$?
      if [ "$code" -ne 3 ] || [[ "$message" != *"lacks x86-64-v3"* ]]; then
        echo "FAIL: $program on a CPU without AVX2: exit $code, stderr: $message"
        status=1
      else
        echo "$program: exit 3, \"${message%%;*}\""
      fi
    done
    exit $status
    ;;
  *)
    echo "usage: $0 avx512-only-in-its-variant|runs-without-avx512|refuses-older-cpus BUILD_DIR" >&2
    exit 2
    ;;
esac
