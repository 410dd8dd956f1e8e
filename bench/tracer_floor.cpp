// rcfd-bench tracer-floor: the least a tracer step can cost in the motion kernel's data layout. The
// paper-scale case of `rcfd-bench tracers` (TracerBenchCase.hpp), tracers placed and sorted by cell
// as the real run does, and only what the integrator itself cannot do without: per block of 64, locate
// the positions (double) and sample u_P^rec from the 4-float step field with the kernel's own
// locateBlock()/sampleBlock() (BlockSampling.hpp), once for Euler and twice for the midpoint rule,
// then write the moved positions. No walls, no Eq. (10), no sub-steps, no cells for the next step.
// The moved positions go to a second array, so every step reads the same sorted cloud.
// Against `rcfd-bench tracers`, it says how much of a step is the layout and how much everything else.
// Two of the kernel's other parts can be added to the midpoint floor, each with the kernel's own
// function: the Eq. (10) direction (the tracer's cell read, its cell's speed gathered,
// counterUnitVector()) and the cells of the moved positions for the next step (CellIndexer::cellsOf()).
// `midpoint_float` prices the midpoint floor with the lanes' arithmetic in float (positions stay double;
// grid coordinates, velocities and displacements are float, so a vector holds 16 lanes instead of 8);
// the kernel locates and takes midpoints in float grid coordinates as it does, with the same functions, and keeps its displacements in double. `midpoint_float_fluctuation_next_cells` adds
// the Eq. (10) direction in float (counterUnitVectorFloat(), as the kernel) and the next cells to it: the
// floor of the kernel's own arithmetic, which no walls and no sub-steps can undercut.
// `midpoint_gradient` prices a one-sample second-order step (floorStepGradient());
// `error_against_16_substeps` gives the position error of one step of each against a reference.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <iterator>
#include <vector>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "BenchRegistry.hpp"
#include "TracerBenchCase.hpp"
#include "tracers/BlockSampling.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/FrameSampler.hpp"
#include "tracers/StepField.hpp"
#include "tracers/UnitVectors.hpp"

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
  const std::int32_t* cell;     ///< the tracers' cells (as the kernel reads them from the last step)
  const float* speed;           ///< |u_fluc| per cell [m/s]
  const std::int32_t* ids;
  std::int32_t* nextCell;       ///< the moved positions' cells
  const CellIndexer* indexer;
};

/// Which of the kernel's parts beyond the samples a floor step adds.
struct FloorParts {
  bool fluctuation = false;  ///< Eq. (10): cell, speed, direction
  bool nextCells = false;    ///< the moved positions' cells
};

/// One step of the floor: `samples` = 1 (Euler) or 2 (midpoint), plus `parts`.
void floorStep(const FloorCase& c, int samples, FloorParts parts, const CounterRngPrefix& prefix) {
  const std::int64_t blocks = (c.n + kBlock - 1) / kBlock;
  constexpr std::int64_t kChunk = 16;  // blocks, as the motion kernel's dynamic chunks
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t chunk = 0; chunk < (blocks + kChunk - 1) / kChunk; ++chunk) {
    block::BlockStencils s;
    alignas(64) double ux[kBlock], uy[kBlock], uz[kBlock];
    alignas(64) double mx[kBlock], my[kBlock], mz[kBlock];
    alignas(64) double ax[kBlock] = {}, ay[kBlock] = {}, az[kBlock] = {};
    for (std::int64_t b = chunk * kChunk; b < std::min(blocks, (chunk + 1) * kChunk); ++b) {
      const std::int64_t i0 = b * kBlock;
      const int m = int(std::min<std::int64_t>(kBlock, c.n - i0));
      if (parts.fluctuation) {
        // Plain locals, as in the kernel: the vectoriser does not look through members or references.
        const CounterRngPrefix rng = prefix;
        const float* const speedOf = c.speed;
        const std::int32_t* const ids = c.ids + i0;
        alignas(64) std::int32_t cellOf[kBlock];
        for (int k = 0; k < m; ++k) cellOf[k] = c.cell[i0 + k];
#pragma omp simd
        for (int k = 0; k < m; ++k) {
          const double speed = double(speedOf[cellOf[k]]);
          double nx, ny, nz;
          counterUnitVector(rng, std::uint64_t(ids[k]), nx, ny, nz);
          ax[k] = speed * nx, ay[k] = speed * ny, az[k] = speed * nz;
        }
      }
      locateBlock(c.q, m, c.x + i0, c.y + i0, c.z + i0, s);
      sampleBlock(c.field, c.corners, s, m, ax, ay, az, ux, uy, uz);
      if (samples == 2) {
        const double half = 0.5 * c.dt;
#pragma omp simd
        for (int k = 0; k < m; ++k) {
          mx[k] = c.x[i0 + k] + half * ux[k], my[k] = c.y[i0 + k] + half * uy[k], mz[k] = c.z[i0 + k] + half * uz[k];
        }
        locateBlock(c.q, m, mx, my, mz, s);
        sampleBlock(c.field, c.corners, s, m, ax, ay, az, ux, uy, uz);
      }
#pragma omp simd
      for (int k = 0; k < m; ++k) {
        c.outX[i0 + k] = c.x[i0 + k] + c.dt * ux[k];
        c.outY[i0 + k] = c.y[i0 + k] + c.dt * uy[k];
        c.outZ[i0 + k] = c.z[i0 + k] + c.dt * uz[k];
      }
    }
    if (parts.nextCells) {  // as the kernel: per chunk, while the moved positions are in cache
      const std::int64_t first = chunk * kChunk * kBlock, last = std::min(c.n, (chunk + 1) * kChunk * kBlock);
      c.indexer->cellsOf(int(last - first), c.outX + first, c.outY + first, c.outZ + first, c.nextCell + first);
    }
  }
}

/// u += u_fluc for the lanes of a block, in float (the kernel adds it in sampleBlockFloat()).
inline void addFluctuation(int m, const float* ax, const float* ay, const float* az, float* ux, float* uy, float* uz) {
#pragma omp simd
  for (int k = 0; k < m; ++k) ux[k] += ax[k], uy[k] += ay[k], uz[k] += az[k];
}

/// The midpoint floor with float lanes: grid coordinates from the double positions once, the midpoint
/// and the displacement in float, the positions updated in double. With `parts`, the kernel's Eq. (10)
/// in float (counterUnitVectorFloat() times the cell's speed, added to both samples) and the next cells:
/// the floor of the kernel's own arithmetic, with no walls and no sub-steps.
void floorStepFloat(const FloorCase& c, FloorParts parts, const CounterRngPrefix& prefix) {
  const std::int64_t blocks = (c.n + kBlock - 1) / kBlock;
  constexpr std::int64_t kChunk = 16;
  const block::GridConstants grid(c.q);
  const float fix = grid.fix, fiy = grid.fiy, fiz = grid.fiz;
  const float dt = float(c.dt), half = 0.5f * float(c.dt);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t chunk = 0; chunk < (blocks + kChunk - 1) / kChunk; ++chunk) {
    block::BlockStencils s;
    alignas(64) float gx[kBlock], gy[kBlock], gz[kBlock], mx[kBlock], my[kBlock], mz[kBlock];
    alignas(64) float ux[kBlock], uy[kBlock], uz[kBlock];
    alignas(64) float ax[kBlock] = {}, ay[kBlock] = {}, az[kBlock] = {};
    for (std::int64_t b = chunk * kChunk; b < std::min(blocks, (chunk + 1) * kChunk); ++b) {
      const std::int64_t i0 = b * kBlock;
      const int m = int(std::min<std::int64_t>(kBlock, c.n - i0));
      if (parts.fluctuation) {
        const CounterRngPrefix rng = prefix;
        const float* const speedOf = c.speed;
        const std::int32_t* const ids = c.ids + i0;
        const std::int32_t* const cellOf = c.cell + i0;
#pragma omp simd
        for (int k = 0; k < m; ++k) {
          const float speed = speedOf[cellOf[k]];
          float nx, ny, nz;
          counterUnitVectorFloat(rng, std::uint64_t(ids[k]), nx, ny, nz);
          ax[k] = speed * nx, ay[k] = speed * ny, az[k] = speed * nz;
        }
      }
      const double* x = c.x + i0;
      const double* y = c.y + i0;
      const double* z = c.z + i0;
      block::gridCoordinatesOfBlock(grid, m, x, y, z, gx, gy, gz);
      block::locateGridBlock(grid, m, gx, gy, gz, s);
      block::sampleBlock3(c.field, c.corners, s, m, ux, uy, uz);
      if (parts.fluctuation) addFluctuation(m, ax, ay, az, ux, uy, uz);
#pragma omp simd
      for (int k = 0; k < m; ++k) {
        mx[k] = gx[k] + half * ux[k] * fix, my[k] = gy[k] + half * uy[k] * fiy, mz[k] = gz[k] + half * uz[k] * fiz;
      }
      block::locateGridBlock(grid, m, mx, my, mz, s);
      block::sampleBlock3(c.field, c.corners, s, m, ux, uy, uz);
      if (parts.fluctuation) addFluctuation(m, ax, ay, az, ux, uy, uz);
      double* outX = c.outX + i0;
      double* outY = c.outY + i0;
      double* outZ = c.outZ + i0;
#pragma omp simd
      for (int k = 0; k < m; ++k) {
        outX[k] = x[k] + double(dt * ux[k]), outY[k] = y[k] + double(dt * uy[k]), outZ[k] = z[k] + double(dt * uz[k]);
      }
    }
    if (parts.nextCells) {
      const std::int64_t first = chunk * kChunk * kBlock, last = std::min(c.n, (chunk + 1) * kChunk * kBlock);
      c.indexer->cellsOf(int(last - first), c.outX + first, c.outY + first, c.outZ + first, c.nextCell + first);
    }
  }
}

/// A one-sample second-order step, priced: u and its gradient from the same 8 corners of one located
/// sample, x' = x + h (u + h/2 (grad u) u). For a linear field it equals the midpoint rule; on the
/// trilinear field it extrapolates the start cell's interpolant where the midpoint rule samples the
/// cell its midpoint lies in. Not what the kernel does: the floor of a kernel that did (AVX2 only:
/// without it, returns false and moves nothing).
bool floorStepGradient(const FloorCase& c) {
#if defined(__AVX2__) && defined(__FMA__)
  if (!c.corners.pairLoads) return false;
  const std::int64_t blocks = (c.n + kBlock - 1) / kBlock;
  constexpr std::int64_t kChunk = 16;
  const std::int32_t o0 = c.corners.off[0], o2 = c.corners.off[2], o4 = c.corners.off[4], o6 = c.corners.off[6];
  // Gradients per grid coordinate times the inverse spacing: per metre.
  const __m128 inverseSpacing = _mm_setr_ps(float(c.q.ix), float(c.q.iy), float(c.q.iz), 0.0f);
  const __m128 halfStep = _mm_set1_ps(float(0.5 * c.dt));
#pragma omp parallel for schedule(dynamic, 1)
  for (std::int64_t chunk = 0; chunk < (blocks + kChunk - 1) / kChunk; ++chunk) {
    block::BlockStencils s;
    alignas(64) float vx[kBlock], vy[kBlock], vz[kBlock];
    for (std::int64_t b = chunk * kChunk; b < std::min(blocks, (chunk + 1) * kChunk); ++b) {
      const std::int64_t i0 = b * kBlock;
      const int m = int(std::min<std::int64_t>(kBlock, c.n - i0));
      locateBlock(c.q, m, c.x + i0, c.y + i0, c.z + i0, s);
      for (int k = 0; k < m; ++k) {
        const float* f = c.field + 4 * std::int64_t(s.base[k]);
        const __m256 fz = _mm256_set1_ps(s.fz[k]), fy = _mm256_set1_ps(s.fy[k]);
        const __m256 c01 = _mm256_loadu_ps(f + o0), c23 = _mm256_loadu_ps(f + o2);
        const __m256 dz01 = _mm256_sub_ps(_mm256_loadu_ps(f + o4), c01);
        const __m256 dz23 = _mm256_sub_ps(_mm256_loadu_ps(f + o6), c23);
        const __m256 t01 = _mm256_fmadd_ps(fz, dz01, c01), t23 = _mm256_fmadd_ps(fz, dz23, c23);
        const __m256 dy = _mm256_sub_ps(t23, t01);
        const __m256 s01 = _mm256_fmadd_ps(fy, dy, t01);
        const __m256 ez = _mm256_fmadd_ps(fy, _mm256_sub_ps(dz23, dz01), dz01);
        const __m128 fx = _mm_set1_ps(s.fx[k]);
        auto lerpX = [&](__m256 v) {
          const __m128 lo = _mm256_castps256_ps128(v), hi = _mm256_extractf128_ps(v, 1);
          return _mm_fmadd_ps(fx, _mm_sub_ps(hi, lo), lo);
        };
        const __m128 s0 = _mm256_castps256_ps128(s01), s1 = _mm256_extractf128_ps(s01, 1);
        const __m128 gx = _mm_sub_ps(s1, s0);
        const __m128 u = _mm_fmadd_ps(fx, gx, s0);
        const __m128 gy = lerpX(dy), gz = lerpX(ez);
        const __m128 w = _mm_mul_ps(u, inverseSpacing);  // (grad u) u = gx wx + gy wy + gz wz
        __m128 ju = _mm_mul_ps(gx, _mm_shuffle_ps(w, w, 0x00));
        ju = _mm_fmadd_ps(gy, _mm_shuffle_ps(w, w, 0x55), ju);
        ju = _mm_fmadd_ps(gz, _mm_shuffle_ps(w, w, 0xaa), ju);
        const __m128 v = _mm_fmadd_ps(halfStep, ju, u);
        _mm_store_ss(vx + k, v);
        vy[k] = std::bit_cast<float>(_mm_extract_ps(v, 1));
        vz[k] = std::bit_cast<float>(_mm_extract_ps(v, 2));
      }
#pragma omp simd
      for (int k = 0; k < m; ++k) {
        c.outX[i0 + k] = c.x[i0 + k] + c.dt * double(vx[k]);
        c.outY[i0 + k] = c.y[i0 + k] + c.dt * double(vy[k]);
        c.outZ[i0 + k] = c.z[i0 + k] + c.dt * double(vz[k]);
      }
    }
  }
  return true;
#else
  (void)c;
  return false;
#endif
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
  // The tracers' cells and a speed of Eq. (10) in every cell (its value does not change the cost).
  const CellIndexer indexer(grid);
  std::vector<std::int32_t> cells(count), nextCells(count);
  indexer.cellsOf(int(n), cloud.x.data(), cloud.y.data(), cloud.z.data(), cells.data());
  const std::vector<float> speed(std::size_t(grid.cellCount()), 0.01f);
  FloorCase c{field.floats(), {}, sampler.locator().constants(), cloud.x.data(), cloud.y.data(), cloud.z.data(),
              outX.data(), outY.data(), outZ.data(), n, bench.scene.rcfd.dt, cells.data(), speed.data(),
              cloud.id.data(), nextCells.data(), &indexer};
  c.corners.set(sampler.locator().offsets32());
  const CounterRngPrefix prefix(1, RngPurpose::Fluctuation, 7);
  const int steps = options.quick ? 10 : 100;
  nlohmann::json out;
  out["tracers"] = n;
  out["cells"] = bench.cells;
  out["field"] = bench.field;
  out["field_statistics"] = bench.statistics;
  out["steps"] = steps;
  struct Variant {
    const char* name;
    int samples;  ///< 1 Euler, 2 midpoint; 0: the midpoint with float lanes (floorStepFloat); -1 floorStepGradient
    FloorParts parts;
  };
  const Variant variants[] = {{"midpoint", 2, {}},
                              {"euler", 1, {}},
                              {"midpoint_fluctuation", 2, {true, false}},
                              {"midpoint_next_cells", 2, {false, true}},
                              {"midpoint_fluctuation_next_cells", 2, {true, true}},
                              {"midpoint_float", 0, {}},
                              {"midpoint_float_fluctuation_next_cells", 0, {true, true}},
                              {"midpoint_gradient", -1, {}}};
  auto stepOf = [&](const Variant& v) {
    if (v.samples == 0) {
      floorStepFloat(c, v.parts, prefix);
    } else if (v.samples < 0) {
      floorStepGradient(c);
    } else {
      floorStep(c, v.samples, v.parts, prefix);
    }
  };
  constexpr std::size_t kVariants = std::size(variants);
  for (const Variant& v : variants) stepOf(v);  // untimed: first touch of the output pages
  // The variants take turns step by step, so the VM's drift (up to 30% within minutes) falls on all.
  double wall[kVariants] = {}, cpu[kVariants] = {};
  for (int k = 0; k < steps; ++k) {
    for (std::size_t j = 0; j < kVariants; ++j) {
      const double cpu0 = processCpuSeconds();
      const auto t0 = std::chrono::steady_clock::now();
      stepOf(variants[j]);
      wall[j] += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / steps;
      cpu[j] += (processCpuSeconds() - cpu0) / steps;
    }
  }
  const bool gradientRuns = floorStepGradient(c);  // false without AVX2: no figure rather than a no-op's
  for (std::size_t j = 0; j < kVariants; ++j) {
    const Variant& v = variants[j];
    if (v.samples < 0 && !gradientRuns) {
      std::cerr << "floor, " << v.name << ": not available (needs AVX2 and FMA)\n";
      continue;
    }
    std::cerr << "floor, " << v.name << ": " << wall[j] * 1e3 << " ms/step, " << cpu[j] * 1e3 << " CPU-ms/step, "
              << cpu[j] / double(n) * 1e9 << " CPU ns per tracer-step\n";
    out[v.name] = {{"ms_per_step", wall[j] * 1e3},
                   {"cpu_ms_per_step", cpu[j] * 1e3},
                   {"cpu_ns_per_tracer_step", cpu[j] / double(n) * 1e9},
                   {"tracer_steps_per_s", double(n) / wall[j]}};
  }
  // The one-sample step and the midpoint rule against a reference (the midpoint rule in 16 sub-steps),
  // one step from the same positions, no walls: RMS and largest position error [m], and the RMS
  // displacement they compare with. The floor does not sub-step, so at Courant numbers above 1 both
  // err more than in the kernel.
  const StepFieldSampler exact(field, sampler.locator());
  constexpr int kReferenceSubsteps = 16;
  std::vector<Eigen::Vector3d> reference(count);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    Eigen::Vector3d p(cloud.x[std::size_t(i)], cloud.y[std::size_t(i)], cloud.z[std::size_t(i)]);
    const double h = c.dt / kReferenceSubsteps;
    for (int k = 0; k < kReferenceSubsteps; ++k) p += h * exact.sample(p + 0.5 * h * exact.sample(p));
    reference[std::size_t(i)] = p;
  }
  auto errors = [&](const char* name) {
    double error2 = 0.0, largest = 0.0, move2 = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      const Eigen::Vector3d p(outX[i], outY[i], outZ[i]);
      const Eigen::Vector3d start(cloud.x[i], cloud.y[i], cloud.z[i]);
      error2 += (p - reference[i]).squaredNorm(), largest = std::max(largest, (p - reference[i]).norm());
      move2 += (reference[i] - start).squaredNorm();
    }
    out["error_against_16_substeps"][name] = {{"rms_m", std::sqrt(error2 / double(count))},
                                              {"max_m", largest},
                                              {"rms_displacement_m", std::sqrt(move2 / double(count))}};
    std::cerr << name << " against the midpoint rule in " << kReferenceSubsteps << " sub-steps, one step: RMS error "
              << std::sqrt(error2 / double(count)) << " m, largest " << largest << " m (RMS displacement "
              << std::sqrt(move2 / double(count)) << " m)\n";
  };
  floorStep(c, 2, {}, prefix);
  errors("midpoint");
  floorStep(c, 1, {}, prefix);
  errors("euler");
  if (gradientRuns) {
    floorStepGradient(c);
    errors("midpoint_gradient");
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
