#pragma once
/// \file JobSupport.hpp
/// Small helpers the job runners share: the OpenMP thread count of the calling thread, reading a
/// JSON file a job wrote earlier (summaries, resume keys) and the grid of the XDMF sidecars.

#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/Xdmf.hpp"
#include "geometry/CartesianGrid.hpp"

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

inline nlohmann::json readJsonFile(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

/// `grid` as the XDMF writer takes it (core knows no CartesianGrid).
inline xdmf::CellGrid xdmfGrid(const CartesianGrid& grid) {
  xdmf::CellGrid g;
  for (int d = 0; d < 3; ++d) {
    g.origin[std::size_t(d)] = grid.origin[d];
    g.spacing[std::size_t(d)] = grid.spacing[d];
    g.shape[std::size_t(d)] = grid.shape[std::size_t(d)];
  }
  return g;
}

}  // namespace rcfd
