#pragma once
/// \file GridVtk.hpp
/// Cell fields on the uniform grid as legacy ASCII VTK files (STRUCTURED_POINTS with CELL_DATA), which
/// ParaView and VisIt open directly. What `rcfd-solve geometry --vtk` writes.

#include <string>
#include <vector>

#include "geometry/Apparatus.hpp"
#include "geometry/CartesianGrid.hpp"

namespace rcfd {

/// Writes `fractions` (one per cell, C order with x fastest, as from openFractions()) as the cell
/// scalar `open_fraction`. Throws std::invalid_argument if the size does not match the grid and
/// rcfd::RunError if the file cannot be written.
void writeOpenFractionVtk(const Apparatus& apparatus, const CartesianGrid& grid,
                          const std::vector<double>& fractions, const std::string& path);

}  // namespace rcfd
