#pragma once
// Shared set-up of the tracer tests: box scenes and analytic in-memory databases.
#include <cmath>
#include <functional>
#include <numbers>

#include "../fields/FieldTestUtil.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "recurrence/RecurrencePath.hpp"
#include "scene/Scene.hpp"
#include "tracers/TracerSimulation.hpp"

namespace rcfd::test {

/// A box scene: size [m], cubic cells of `cell` [m], tracers, dt = dt_rec, given effects. The bed mass
/// is chosen so the tracers fill the box at alpha_P = `alpha` on average.
inline Scene boxScene(const Vec3& size, double cell, long tracers, double dt, std::vector<std::string> effects,
                      double alpha = 0.3) {
  Scene s;
  s.apparatus.type = ApparatusSpec::Type::Box;
  s.apparatus.size = size;
  s.grid.cell_size = Vec3(cell, cell, cell);
  s.rcfd.dt = dt;
  s.rcfd.tracers = tracers;
  s.effects = std::move(effects);
  s.process.bed_mass = alpha * size.prod() * s.particles.density;
  s.probes.clear();
  return s;
}

inline CartesianGrid gridOf(const Scene& s) {
  Apparatus a(s.apparatus);
  return makeGrid(a, s.grid);
}

inline std::shared_ptr<FieldDatabase> database(const Scene& s, int frames, double dtRec, const FrameFunction& fill) {
  Apparatus a(s.apparatus);
  const CartesianGrid grid = makeGrid(a, s.grid);
  const auto open = openFractions(a, grid);
  std::vector<float> fluid(open.begin(), open.end());
  return makeAnalyticDatabase(grid, fluid, dtRec, frames, fill);
}

/// The path 0, 1, 2, ... (mod frames) of `length` entries: one long sequence, wrapping with a jump.
inline RecurrencePath sequentialPath(int frames, std::int64_t length) {
  RecurrencePath p;
  p.frames.resize(std::size_t(length));
  for (std::int64_t i = 0; i < length; ++i) p.frames[std::size_t(i)] = int(i % frames);
  return p;
}

}  // namespace rcfd::test
