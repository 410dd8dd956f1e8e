// rcfd-bench dem: a dense settling bed of 20,000 spheres (1.8 mm, the paper's material, Hertz-Mindlin
// with tangential history, cdt rolling friction) in a box; figure: particle steps per second.
// The same initial state is written for LIGGGHTS (bench/liggghts/, docs/performance.md).
#include <chrono>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <omp.h>
#include <random>
#include <spdlog/spdlog.h>

#include "BenchRegistry.hpp"
#include "cfddem/DemSystem.hpp"

namespace rcfd::bench {
namespace {

using Eigen::Vector3d;

/// The benchmark case: a loose lattice (spacing 1.05 d, jittered) collapsed into a dense bed, then
/// timed while it rests and settles further.
struct DemBenchCase {
  int nx = 25, ny = 32, nz = 25;  // 20,000 spheres
  double d = 1.8e-3;
  double spacing = 1.05 * 1.8e-3;
  double dt = 1e-5;               // 0.14 of the Rayleigh time of the 1.8 mm sphere (Y = 5 MPa)
  Vector3d lo() const { return Vector3d(0, 0, 0); }
  Vector3d hi() const { return Vector3d(nx * spacing, (ny + 6) * spacing, nz * spacing); }
  std::vector<Vector3d> positions() const {
    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> u(-0.02 * d, 0.02 * d);
    std::vector<Vector3d> x;
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (int i = 0; i < nx; ++i)
          x.emplace_back((i + 0.5) * spacing + u(rng), (j + 0.5) * spacing, (k + 0.5) * spacing + u(rng));
    return x;
  }
};

DemMaterial benchMaterial(const DemBenchCase& c) {
  return DemMaterial::make(1040.0, 5e6, 0.25, 0.5 * c.d, ContactPair{0.9, 0.75},
                           ContactPair{0.5, 0.24}, ContactPair{0.06, 0.05});
}

DemSettings benchSettings(double dt) {
  DemSettings s;
  s.time_step = dt;
  s.rolling_model = "cdt";
  s.max_overlap_fraction = 1.0;
  s.skin_fraction = 0.4;
  // RCFD_BENCH_DEM_DIRECT=1 (with --threads 1): the serial reference scheme without the
  // deterministic per-pair gather, to measure what determinism costs.
  if (const char* d = std::getenv("RCFD_BENCH_DEM_DIRECT"); d && std::string(d) == "1")
    s.serial_direct_accumulation = true;
  return s;
}

/// The dense bed: the jittered lattice collapsed under gravity and settled (untimed; cached in
/// $TMPDIR because it takes a minute).
std::vector<Vector3d> denseBed(const DemBenchCase& c) {
  const char* tmp = std::getenv("TMPDIR");
  const std::string cache = std::string(tmp ? tmp : "/tmp") + "/rcfd-bench-dem-bed-" +
                            std::to_string(c.nx) + "x" + std::to_string(c.ny) + "x" +
                            std::to_string(c.nz) + ".txt";
  std::vector<Vector3d> x;
  if (std::ifstream in(cache); in) {
    Vector3d p;
    while (in >> p.x() >> p.y() >> p.z()) x.push_back(p);
    if (x.size() == static_cast<std::size_t>(c.nx) * c.ny * c.nz) return x;
    x.clear();
  }
  const auto t0 = std::chrono::steady_clock::now();
  DemSystem dem(benchMaterial(c), DemWalls::box(c.lo(), c.hi()), benchSettings(2e-5));
  for (const auto& p : c.positions()) dem.addParticle(p);
  dem.run(6000);  // 0.12 s: the lattice has collapsed and the bed is at rest
  std::cout << "prepared the dense bed in "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()
            << " s (kinetic energy " << dem.particles().kineticEnergy() << " J), cached in " << cache
            << "\n";
  std::ofstream out(cache);
  out.precision(17);
  for (const auto& p : dem.particles().x) out << p.x() << " " << p.y() << " " << p.z() << "\n";
  return dem.particles().x;
}

/// Writes a state as a LAMMPS/LIGGGHTS data file (atom_style granular: id type diameter density
/// x y z).
void writeLiggghtsData(const DemBenchCase& c, const std::vector<Vector3d>& x, const std::string& path) {
  std::ofstream f(path);
  const Vector3d hi = c.hi();
  f.precision(17);
  f << "rcfd-bench dem initial state\n\n" << x.size() << " atoms\n2 atom types\n\n";
  f << "0 " << hi.x() << " xlo xhi\n0 " << hi.y() << " ylo yhi\n0 " << hi.z() << " zlo zhi\n\nAtoms\n\n";
  for (std::size_t i = 0; i < x.size(); ++i)
    f << i + 1 << " 1 " << c.d << " 1040 " << x[i].x() << " " << x[i].y() << " " << x[i].z() << "\n";
}

nlohmann::json run(const Options& opt) {
  spdlog::set_level(spdlog::level::warn);
  DemBenchCase c;
  if (opt.quick) c.ny = 8;  // 5,000 spheres
  const long steps = opt.quick ? 200 : 2000;
  const auto bed = denseBed(c);
  if (const char* path = std::getenv("RCFD_BENCH_DEM_DATA")) {
    writeLiggghtsData(c, bed, path);
    std::cout << "wrote the initial state for LIGGGHTS to " << path << "\n";
  }
  DemSystem dem(benchMaterial(c), DemWalls::box(c.lo(), c.hi()), benchSettings(c.dt));
  std::vector<std::size_t> order(bed.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  // RCFD_BENCH_DEM_SHUFFLE=1: random particle order, as after random insertion and mixing.
  if (const char* sh = std::getenv("RCFD_BENCH_DEM_SHUFFLE"); sh && std::string(sh) == "1")
    std::shuffle(order.begin(), order.end(), std::mt19937_64(1));
  for (std::size_t i : order) dem.addParticle(bed[i]);
  const long n = static_cast<long>(dem.particles().size());
  const auto t0 = std::chrono::steady_clock::now();
  dem.run(steps);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = static_cast<double>(n) * steps / wall;
  std::cout << "dem: " << n << " spheres, " << steps << " steps of " << c.dt << " s in " << wall
            << " s: " << rate << " particle-steps/s (" << omp_get_max_threads() << " threads), "
            << dem.lastStats().contacts << " contacts at the end, " << dem.neighbourList().builds()
            << " list builds\n";
  double ymax = 0.0;
  for (const auto& x : dem.particles().x) ymax = std::max(ymax, x.y());
  const DemTimings& tm = dem.timings();
  std::cout << "phases [s]: drift " << tm.drift << ", list builds " << tm.build << ", pair forces "
            << tm.pairs << ", gather + walls + kick " << tm.gather << "\n";
  return {{"particle_steps_per_s", rate},
          {"particles", n},
          {"steps", steps},
          {"time_step_s", c.dt},
          {"wall_time_s", wall},
          {"contacts_end", dem.lastStats().contacts},
          {"wall_contacts_end", dem.lastStats().wall_contacts},
          {"list_builds", dem.neighbourList().builds()},
          {"max_overlap_fraction", dem.maxOverlapFractionSeen()},
          {"bed_top_m", ymax},
          {"kinetic_energy_j", dem.particles().kineticEnergy()},
          {"phase_seconds", {{"drift", tm.drift}, {"build", tm.build}, {"pairs", tm.pairs},
                             {"gather_walls_kick", tm.gather}}}};
}

const bool registered = addBenchmark(
    "dem", "dense settling bed of 20,000 spheres, Hertz-Mindlin + history + cdt rolling friction", run);

}  // namespace
}  // namespace rcfd::bench

// rcfd-bench dem-procell: the acceptance case of issue 6, 1.5 kg of the paper's particles at cg = 3
// (17,494 parcels) poured into the ProCell (no draft plates, the scene default) from the paper's
// region 0.2 m < y < 0.3 m and settled; reports parcels outside the walls or inside the inlet.
#include "cfddem/ApparatusWalls.hpp"
#include "cfddem/DemFilling.hpp"
#include "geometry/Apparatus.hpp"

namespace rcfd::bench {
namespace {

nlohmann::json runProCell(const Options& opt) {
  spdlog::set_level(spdlog::level::info);
  Scene scene;
  scene.dem.coarse_graining = opt.quick ? 8.0 : 3.0;
  const DemMaterial m = DemMaterial::fromScene(scene);
  DemSettings s = DemSystem::settingsFromScene(scene);
  s.rolling_model = "cdt";
  s.time_step = 0.25 * m.rayleighTime();  // the paper's 1 us would take 50x longer to settle
  const Apparatus apparatus(scene.apparatus);
  DemSystem dem(m, wallsFromApparatus(apparatus), s);
  const long n = parcelsForBedMass(scene);
  const auto t0 = std::chrono::steady_clock::now();
  FillOptions fo;
  fo.max_settle_time = 1.0;
  const FillResult r = fillAndSettle(dem, defaultFillRegion(scene.apparatus), n, fo);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Independent check with the apparatus's own signed distance (not the DEM wall primitives).
  long outside = 0, in_inlet = 0;
  double top = 0.0, mass = 0.0, min_clear = 1.0;
  for (std::size_t i = 0; i < dem.particles().size(); ++i) {
    const Vector3d& x = dem.particles().x[i];
    const double c = apparatus.signedDistance(x);
    min_clear = std::min(min_clear, c / m.particle_radius);
    if (c < 0.0) ++outside;
    if (x.y() < 0.0) ++in_inlet;
    top = std::max(top, x.y());
    mass += dem.particles().mass[i];
  }
  std::cout << "dem-procell: " << r.inserted << " parcels (cg " << scene.dem.coarse_graining << ", "
            << mass << " kg) in " << r.batches << " batches, " << r.fill_time << " s falling + "
            << r.settle_time << " s settling (" << (r.settled ? "settled" : "time limit") << "), "
            << dem.steps() << " steps in " << wall << " s; bed top y = " << top << " m; " << outside
            << " outside the walls, " << in_inlet << " in the inlet; closest centre "
            << min_clear << " r from a wall\n";
  return {{"parcels", r.inserted}, {"coarse_graining", scene.dem.coarse_graining},
          {"bed_mass_kg", mass}, {"batches", r.batches}, {"fill_time_s", r.fill_time},
          {"settle_time_s", r.settle_time}, {"settled", r.settled}, {"steps", dem.steps()},
          {"time_step_s", s.time_step}, {"rayleigh_fraction", dem.rayleighFraction()},
          {"wall_time_s", wall}, {"bed_top_m", top}, {"outside_walls", outside},
          {"in_inlet", in_inlet}, {"closest_centre_over_radius", min_clear},
          {"max_overlap_fraction", dem.maxOverlapFractionSeen()},
          {"particle_steps_per_s", static_cast<double>(dem.particles().size()) * dem.steps() / wall}};
}

const bool registered_procell = addBenchmark(
    "dem-procell", "1.5 kg at cg = 3 poured into the ProCell and settled (issue 6 acceptance)",
    runProCell);

}  // namespace
}  // namespace rcfd::bench
