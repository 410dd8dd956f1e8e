#pragma once
/// \file XdmfGrid.hpp
/// A CartesianGrid as the XDMF sidecar writer (core/Xdmf.hpp, which knows no CartesianGrid) takes it.

#include "core/Xdmf.hpp"
#include "geometry/CartesianGrid.hpp"

namespace rcfd {

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
