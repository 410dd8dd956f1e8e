// rcfd-bench tracer-floor: the least a tracer step can cost in the motion kernel's data layout. The
// paper-scale case of `rcfd-bench tracers` (TracerBenchCase.hpp), tracers placed and sorted by cell
// as the real run does, and only what the integrator itself cannot do without: per block of 64, locate
// the positions (double) and sample u_P^rec from the 4-float step field with the kernel's own
// locateBlock()/sampleBlock() (BlockSampling.hpp), once for Euler and twice for the midpoint rule,
// then write the moved positions. No walls, no Eq. (10), no sub-steps, no cells for the next step.
// The moved positions go to a second array, so every step reads the same sorted cloud.
// Against `rcfd-bench tracers`, it says how much of a step is the layout and how much everything else.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <iostream>
#include <vector>

#include "BenchRegistry.hpp"
#include "TracerBenchCase.hpp"
#include "tracers/BlockSampling.hpp"
#include "tracers/FrameSampler.hpp"
#include "tracers/StepField.hpp"

namespace rcfd::bench {
namespace {

using block::kBlock;

struct FloorCase {
  const float* field;
  block::CornerOffsets corners;
  TrilinearLocator::Constants q;
  const double *x, *y, *z;
  double *outX, *outY, *outZ;
  std::int64_t n;
  double dt;
};

/// One step of the floor: `samples` = 1 (Euler) or 2 (midpoint).
void floorStep(const FloorCase& c, int samples) {
  const std::int64_t blocks = (c.n + kBlock - 1) / kBlock;
  constexpr std::int64_t kChunk = 16;  // blocks, as the motion kernel's dynamic chunks
  static constexpr double kZero[kBlock] = {};
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t chunk = 0; chunk < (blocks + kChunk - 1) / kChunk; ++chunk) {
    block::BlockStencils s;
    alignas(64) double ux[kBlock], uy[kBlock], uz[kBlock];
    alignas(64) double mx[kBlock], my[kBlock], mz[kBlock];
    for (std::int64_t b = chunk * kChunk; b < std::min(blocks, (chunk + 1) * kChunk); ++b) {
      const std::int64_t i0 = b * kBlock;
      const int m = int(std::min<std::int64_t>(kBlock, c.n - i0));
      locateBlock(c.q, m, c.x + i0, c.y + i0, c.z + i0, s);
      sampleBlock(c.field, c.corners, s, m, kZero, kZero, kZero, ux, uy, uz);
      if (samples == 2) {
        const double half = 0.5 * c.dt;
#pragma omp simd
        for (int k = 0; k < m; ++k) {
          mx[k] = c.x[i0 + k] + half * ux[k], my[k] = c.y[i0 + k] + half * uy[k], mz[k] = c.z[i0 + k] + half * uz[k];
        }
        locateBlock(c.q, m, mx, my, mz, s);
        sampleBlock(c.field, c.corners, s, m, kZero, kZero, kZero, ux, uy, uz);
      }
#pragma omp simd
      for (int k = 0; k < m; ++k) {
        c.outX[i0 + k] = c.x[i0 + k] + c.dt * ux[k];
        c.outY[i0 + k] = c.y[i0 + k] + c.dt * uy[k];
        c.outZ[i0 + k] = c.z[i0 + k] + c.dt * uz[k];
      }
    }
  }
}

nlohmann::json run(const Options& options) {
  TracerBenchCase bench(options);
  // The tracers as the real run has them: placed, and sorted by cell at the first step.
  TracerRunSettings settings{1, 2, 0, true};
  TracerSimulation sim(bench.scene, bench.db, RecurrencePath{{0, 1, 2, 3}}, settings);
  sim.step();
  const TracerCloud& cloud = sim.cloud();
  const std::int64_t n = std::int64_t(cloud.size());
  Apparatus apparatus(bench.scene.apparatus);
  const CartesianGrid grid = makeGrid(apparatus, bench.scene.grid);
  const auto frame = bench.db->frame(1);
  const FrameSampler sampler(grid, frame.get());
  StepVelocityField field;
  field.build(sampler, false, true);
  const std::size_t count = std::size_t(n);
  std::vector<double> outX(count), outY(count), outZ(count);
  FloorCase c{field.floats(), {}, sampler.locator().constants(), cloud.x.data(), cloud.y.data(), cloud.z.data(),
              outX.data(), outY.data(), outZ.data(), n, bench.scene.rcfd.dt};
  c.corners.set(sampler.locator().offsets32());
  const int steps = options.quick ? 10 : 100;
  nlohmann::json out;
  out["tracers"] = n;
  out["cells"] = bench.cells;
  out["steps"] = steps;
  for (const int samples : {2, 1}) {
    floorStep(c, samples);  // untimed: first touch of the output pages
    const double cpu0 = processCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < steps; ++k) floorStep(c, samples);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / steps;
    const double cpu = (processCpuSeconds() - cpu0) / steps;
    const std::string name = samples == 2 ? "midpoint" : "euler";
    std::cerr << "floor, " << name << " (" << samples << " sample" << (samples == 2 ? "s" : "") << " per tracer-step): "
              << wall * 1e3 << " ms/step, " << cpu * 1e3 << " CPU-ms/step, " << cpu / double(n) * 1e9
              << " CPU ns per tracer-step\n";
    out[name] = {{"ms_per_step", wall * 1e3},
                 {"cpu_ms_per_step", cpu * 1e3},
                 {"cpu_ns_per_tracer_step", cpu / double(n) * 1e9},
                 {"tracer_steps_per_s", double(n) / wall}};
  }
  double checksum = 0.0;  // keeps the stores observable
  for (std::int64_t i = 0; i < n; i += 997) checksum += outX[std::size_t(i)] + outY[std::size_t(i)] + outZ[std::size_t(i)];
  out["position_checksum"] = checksum;
  return out;
}

const bool registered = addBenchmark(
    "tracer-floor",
    "the least a tracer step costs in the motion kernel's layout: locate + 1 or 2 samples + move, nothing else",
    run);

}  // namespace
}  // namespace rcfd::bench
