#include "geometry/GridVtk.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "core/Errors.hpp"

namespace rcfd {

void writeOpenFractionVtk(const Apparatus& apparatus, const CartesianGrid& grid,
                          const std::vector<double>& fractions, const std::string& path) {
  if (std::int64_t(fractions.size()) != grid.cellCount())
    throw std::invalid_argument("writeOpenFractionVtk: " + std::to_string(fractions.size()) +
                                " values for " + std::to_string(grid.cellCount()) + " cells");
  std::ofstream out(path);
  if (!out) throw RunError("cannot write " + path);
  const bool box = apparatus.spec().type == ApparatusSpec::Type::Box;
  char line[256];
  out << "# vtk DataFile Version 3.0\n"
      << "rcfd open fraction of the " << (box ? "box" : "prismatic spouted bed") << " grid [-]\n"
      << "ASCII\nDATASET STRUCTURED_POINTS\n";
  // Legacy VTK counts points; cells are one fewer along each axis.
  std::snprintf(line, sizeof line, "DIMENSIONS %d %d %d\n", grid.shape[0] + 1, grid.shape[1] + 1,
                grid.shape[2] + 1);
  out << line;
  std::snprintf(line, sizeof line, "ORIGIN %.17g %.17g %.17g\n", grid.origin.x(), grid.origin.y(),
                grid.origin.z());
  out << line;
  std::snprintf(line, sizeof line, "SPACING %.17g %.17g %.17g\n", grid.spacing.x(), grid.spacing.y(),
                grid.spacing.z());
  out << line;
  out << "CELL_DATA " << grid.cellCount() << "\nSCALARS open_fraction double 1\nLOOKUP_TABLE default\n";
  // x fastest, as VTK expects for structured points.
  for (std::size_t c = 0; c < fractions.size(); ++c) {
    std::snprintf(line, sizeof line, "%.9g", fractions[c]);
    out << line << ((c + 1) % std::size_t(grid.shape[0]) == 0 ? '\n' : ' ');
  }
  if (!out) throw RunError("failed writing " + path);
}

}  // namespace rcfd
