# Tuning for -march=native builds on CPUs newer than the compiler knows.
#
# GCC 12 (Debian 12) does not know Intel's Emerald Rapids (family 6, model 207): -march=native turns on
# its instruction sets, AVX-512 included, but tunes for "generic", which emulates every gather with
# scalar loads. The motion kernel gathers per lane (a cell's reach and speed, the sub-step lengths),
# and tuned for the nearest CPU GCC knows it runs 1.09-1.13x as fast on such a machine, with the same
# results (docs/performance.md, "Tracers", build tuning). AMD CPUs are left alone: their gathers are slow
# and no measurement says which tuning suits them.
#
# Sets RCFD_NATIVE_TUNING to the extra flags (empty where none are needed).
function(rcfd_native_tuning)
  set(flags "")
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND EXISTS /proc/cpuinfo)
    execute_process(COMMAND ${CMAKE_CXX_COMPILER} -march=native -Q --help=target
                    OUTPUT_VARIABLE target ERROR_QUIET RESULT_VARIABLE failed)
    file(STRINGS /proc/cpuinfo vendor LIMIT_COUNT 1 REGEX "^vendor_id")
    if(NOT failed AND target MATCHES "-mtune=[ \t]+generic" AND target MATCHES "-mavx512f[ \t]+\\[enabled\\]"
       AND vendor MATCHES "GenuineIntel")
      set(flags -mtune=sapphirerapids -mprefer-vector-width=512)
      list(JOIN flags " " shown)
      message(STATUS "rcfd: ${CMAKE_CXX_COMPILER_ID} tunes this Intel AVX-512 CPU as generic; adding ${shown}")
    endif()
  endif()
  set(RCFD_NATIVE_TUNING "${flags}" PARENT_SCOPE)
endfunction()
