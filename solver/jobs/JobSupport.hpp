#pragma once
/// \file JobSupport.hpp
/// Small helpers the job runners share: the OpenMP thread count of the calling thread, reading a
/// JSON file a job wrote earlier (summaries, resume keys) and the grid of the XDMF sidecars.

#include <cstdint>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "geometry/XdmfGrid.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace rcfd {

/// Threads of the parallel regions the calling thread starts (a per-thread setting, so ensemble members
/// or calibration runs on their own threads each get their share).
inline void setRunThreads(int n) {
#ifdef _OPENMP
  omp_set_num_threads(n);
#else
  (void)n;
#endif
}

/// Frame cache when a job's figures read a database back: a few frames of the largest grids.
inline constexpr std::int64_t kFigureCacheBytes = 256LL << 20;

inline nlohmann::json readJsonFile(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace rcfd
