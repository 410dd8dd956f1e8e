#pragma once
// Scenes for the gas-phase tests: the ProCell quick slice and verification boxes.

#include <memory>

#include "cfddem/gas/GasSolver.hpp"

namespace rcfd::test {

/// The quick slice of examples/quick.json on 5 mm cells (quick.json has 6.67 mm; these tests keep the
/// finer grid their tolerances were set on): 0.02 m deep, 1/10 of the paper's flows.
inline Scene quickSliceScene(bool plates) {
  Scene s;
  s.apparatus.depth = 0.02;
  s.grid.cell_size = Vec3(0.005, 0.005, 0.005);
  s.gas.max_time_step = 5e-5;
  s.process.gas_flow_rate = 0.0063889;
  s.process.atomisation_flow_rate = 0.00013889;
  s.spray.nozzle_position = Vec3(0.0, 0.0, 0.01);
  if (plates) s.apparatus.draft_plates = DraftPlatesSpec{};
  return s;
}

/// A box with its top open (outlet) and no nozzle air.
inline Scene boxScene(const Vec3& size, const Vec3& cell, double flowRate) {
  Scene s;
  s.apparatus.type = ApparatusSpec::Type::Box;
  s.apparatus.size = size;
  s.apparatus.box_outlet_top = true;
  s.grid.cell_size = cell;
  s.process.gas_flow_rate = flowRate;
  s.process.atomisation_flow_rate = 0.0;
  return s;
}

/// Owns the apparatus and grid a GasSolver refers to.
struct GasCase {
  Scene scene;
  Apparatus apparatus;
  CartesianGrid grid;
  std::unique_ptr<gas::GasSolver> solver;
  GasCase(Scene s, gas::GasOptions options = {})
      : scene(std::move(s)), apparatus(scene.apparatus), grid(makeGrid(apparatus, scene.grid)) {
    solver = std::make_unique<gas::GasSolver>(scene, apparatus, grid, options);
  }
};

}  // namespace rcfd::test
