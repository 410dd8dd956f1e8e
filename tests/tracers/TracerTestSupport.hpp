#pragma once
// Shared set-up of the tracer tests: box scenes and analytic in-memory databases.
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <omp.h>
#include <string>

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

/// Gives frame f the optional velocity-spread datasets, zero, for a grid of `cells` cells.
inline void zeroVelocitySpread(FieldFrame& f, std::size_t cells) {
  f.up_fraction.assign(cells, 0.0f);
  f.u_p_up.assign(3 * cells, 0.0f);
  f.u_p_down.assign(3 * cells, 0.0f);
  f.u_p_variance.assign(3 * cells, 0.0f);
}

/// The path 0, 1, 2, ... (mod frames) of `length` entries: one long sequence, wrapping with a jump.
inline RecurrencePath sequentialPath(int frames, std::int64_t length) {
  RecurrencePath p;
  p.frames.resize(std::size_t(length));
  for (std::int64_t i = 0; i < length; ++i) p.frames[std::size_t(i)] = int(i % frames);
  return p;
}

/// `steps` steps of a tracer run on `threads` threads along the sequential path; at step
/// `checkpointAt` (when >= 0) the run is saved to `checkpointFile`, discarded and resumed from it.
inline std::unique_ptr<TracerSimulation> runSteps(const Scene& scene, std::shared_ptr<FieldDatabase> db,
                                                  std::uint64_t seed, std::int64_t steps, int threads,
                                                  std::int64_t checkpointAt, const std::string& checkpointFile) {
  omp_set_num_threads(threads);
  const RecurrencePath path = sequentialPath(db->frameCount(), steps + 2);
  const TracerRunSettings settings{seed, steps, 0};
  auto sim = std::make_unique<TracerSimulation>(scene, db, path, settings);
  for (std::int64_t k = 0; k < steps; ++k) {
    if (k == checkpointAt) {
      const std::string checkpoint = tempPath(checkpointFile);
      sim->saveCheckpoint(checkpoint);
      sim = std::make_unique<TracerSimulation>(scene, db, path, settings);
      sim->loadCheckpoint(checkpoint);
    }
    sim->step();
  }
  omp_set_num_threads(2);
  return sim;
}

}  // namespace rcfd::test
