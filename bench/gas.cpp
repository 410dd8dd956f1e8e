// rcfd-bench gas: the gas phase alone (no particles: alpha_G = 1, no drag) in the ProCell quick slice
// (examples/quick.json: 0.02 m deep, 5 mm cells) and the full 3D ProCell at 5 mm cells, with every
// registered pressure preconditioner (multigrid, incomplete Cholesky, Jacobi). Wall time per step and per simulated second, pressure-CG iterations.
// With a coupling, alpha_G and the drag change every step: the "coupled" rows emulate that with a
// drifting alpha_G and a drag source, which forces matrix rebuilds (and IC refactorisations every
// refactorInterval steps).
#include <chrono>
#include <cmath>
#include <iostream>

#include "BenchRegistry.hpp"
#include "cfddem/gas/GasSolver.hpp"

namespace rcfd::bench {
namespace {

struct GasTiming {
  double msPerStep = 0.0, dt = 0.0, iterations = 0.0, setupMs = 0.0;
};

GasTiming timeGas(Scene scene, const std::string& preconditioner, int warmup, int steps, bool coupled) {
  const auto t0 = std::chrono::steady_clock::now();
  scene.gas.pressure_preconditioner = preconditioner;
  Apparatus apparatus(scene.apparatus);
  const CartesianGrid grid = makeGrid(apparatus, scene.grid);
  gas::GasSolver solver(scene, apparatus, grid, gas::GasOptions{});
  GasTiming t;
  t.setupMs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() * 1e3;
  const std::size_t n = std::size_t(grid.cellCount());
  std::vector<double> alpha(n, 1.0), beta(n, 0.0);
  const std::vector<Eigen::Vector3d> uP(n, Eigen::Vector3d::Zero());
  auto couple = [&](int step) {
    if (!coupled) return;
    // A bed of alpha_G ~ 0.45 below 0.1 m with a slowly moving perturbation and a Beetstra-sized beta.
    for (std::size_t c = 0; c < n; ++c) {
      const auto ijk = grid.cellIjk(std::int64_t(c));
      const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
      const bool bed = p.y() < 0.1 && std::abs(p.x()) > 0.015;
      alpha[c] = bed ? 0.45 + 0.05 * std::sin(50 * p.x() + 0.01 * step) : 1.0;
      beta[c] = bed ? 2e4 : 0.0;
    }
    solver.setGasFraction(alpha);
    solver.setDragSource(beta, uP);
  };
  for (int k = 0; k < warmup; ++k) couple(k), solver.step(1.0);
  long iterations = 0;
  double simulated = 0.0;
  const auto t1 = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) {
    couple(warmup + k);
    simulated += solver.step(1.0);
    iterations += solver.lastStep().pressureIterations;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  t.msPerStep = s / steps * 1e3;
  t.dt = simulated / steps;
  t.iterations = double(iterations) / steps;
  std::cerr << "  " << scene.name << " " << preconditioner << (coupled ? " coupled" : "") << ": " << grid.cellCount()
            << " cells, " << t.msPerStep << " ms/step, dt " << t.dt << " s, " << t.msPerStep / t.dt / 1e3
            << " s wall per simulated s, " << t.iterations << " CG iterations/step (setup " << t.setupMs << " ms)\n";
  return t;
}

nlohmann::json toJson(const GasTiming& t) {
  return {{"ms_per_step", t.msPerStep},
          {"dt", t.dt},
          {"wall_s_per_simulated_s", t.msPerStep / t.dt / 1e3},
          {"pressure_iterations_per_step", t.iterations},
          {"setup_ms", t.setupMs}};
}

nlohmann::json runGas(const Options& options) {
  Scene quick;  // examples/quick.json's gas set-up
  quick.name = "quick-slice";
  quick.apparatus.depth = 0.02;
  quick.gas.max_time_step = 5e-5;
  quick.process.gas_flow_rate = 0.0063889;
  quick.process.atomisation_flow_rate = 0.00013889;
  quick.spray.nozzle_position = Vec3(0.0, 0.0, 0.01);
  Scene full;  // the paper's ProCell: 0.25 x 0.6 x 0.2 m, 230 + 5 m3/h, dt <= 2.5e-5 s
  full.name = "procell-3d";
  const int warm = options.quick ? 20 : 200, steps = options.quick ? 20 : 200;
  const int warm3d = options.quick ? 3 : 20, steps3d = options.quick ? 3 : 20;
  nlohmann::json out;
  for (const std::string& pc : gas::PreconditionerRegistry::names()) {
    out["quick_slice"][pc] = toJson(timeGas(quick, pc, warm, steps, false));
    out["quick_slice_coupled"][pc] = toJson(timeGas(quick, pc, warm, steps, true));
    out["procell_3d"][pc] = toJson(timeGas(full, pc, warm3d, steps3d, false));
  }
  const auto& q = out["quick_slice"]["mg"];
  out["wall_s_per_simulated_s"] = q["wall_s_per_simulated_s"];
  return out;
}

const bool registered = addBenchmark(
    "gas", "gas phase (no particles and emulated coupling): quick slice and 3D ProCell at 5 mm, mg, ic and jacobi",
    runGas);

}  // namespace
}  // namespace rcfd::bench
