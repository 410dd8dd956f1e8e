// The property test across whole jobs (docs/stability.md, "Random whole jobs"): random scenes and job
// files within the schema's ranges -- tiny grids, short durations, every job kind, every effect, every
// apparatus -- each run through rcfd-solve to the end. Every one must end in one of the two allowed
// ways within its time bound: exit 0 with every output finite and bounded, or exit 2 with a message
// naming the field -- or the one documented third: exit 3 of a gas solve that does not reach the
// scene's pressure tolerance, naming time, step, residual and /gas/pressure_tolerance, its checkpoint
// kept. A failing scene prints its seed; the same seed gives the same scene:
//
//   RCFD_PROPERTY_SEED=<seed> RCFD_PROPERTY_SCENES=1 build/tests/rcfd-test-stability --gtest_filter='PropertyJobs.*'
//
// RCFD_PROPERTY_SCENES (default kDefaultScenes) scenes are run from seed RCFD_PROPERTY_SEED (default
// 34; "random" draws one and prints it); RCFD_PROPERTY_KEEP=1 keeps every job's directory.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <map>
#include <random>

#include "StabilityCases.hpp"
#include "cfddem/DemMaterial.hpp"

using namespace rcfd::stability;

namespace {

/// Scenes of the default run: about two minutes on two cores (docs/stability.md).
constexpr long kDefaultScenes = 200;
/// Seconds a job may take before it counts as a hang: the scenes are sized to take well under one.
constexpr double kDefaultTimeBound = 60.0;

long envLong(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::strtol(v, nullptr, 10) : fallback;
}

/// One random job: the job document, and the database file it reads (written by the generator).
class JobGenerator {
 public:
  JobGenerator(std::uint64_t seed, fs::path dir) : rng_(seed), seed_(seed), dir_(std::move(dir)) {}

  json make() {
    const double k = uniform(0.0, 1.0);
    kind_ = k < 0.55 ? "spray" : k < 0.85 ? "database" : "calibration";
    json scene;
    scene["name"] = "property-" + std::to_string(seed_);
    scene["apparatus"] = apparatus();
    scene["grid"] = grid();
    scene["particles"] = particles();
    scene["gas"] = gas();
    scene["process"] = process();
    scene["dem"] = dem();
    scene["spray"] = spray();
    scene["probes"] = probes();
    scene["outputs"] = {{"coverage_bins", integer(1, 60)}, {"residence_time_bins", integer(1, 60)},
                        {"svg", chance(0.15)}};
    if (kind_ == "database") {
      scene["effects"] = databaseEffects();
      json job = {{"kind", "database"}, {"scene", scene}, {"seed", integer(0, 1000000)},
                  {"checkpoint_interval", logUniform(0.005, 1.0)}};
      if (chance(0.01)) job["ensemble"] = 2;  // 1 %: an ensemble outside a spray job (refused)
      return job;
    }
    scene["effects"] = tracerEffects();
    const double dtRec = logUniform(1e-3, 0.05);
    scene["rcfd"] = rcfd(dtRec);
    writeDatabase(scene, dtRec);
    const double dt = scene["rcfd"]["dt"].get<double>();
    const long steps = integer(1, kind_ == "spray" ? 200 : 80);
    json job = {{"kind", kind_},
                {"scene", scene},
                {"database", (dir_ / "db.h5").string()},
                {"duration", double(steps) * dt},
                {"seed", integer(0, 1000000)},
                {"checkpoint_interval", logUniform(dt, 1.0)}};
    if (kind_ == "calibration") {
      json d0 = json::array();
      const long n = integer(1, 3);
      for (long i = 0; i < n; ++i) d0.push_back(chance(0.2) ? 0.0 : logUniform(1e-7, 0.05) * double(i + 1));
      job["d0_values"] = d0;
      job["discard"] = double(integer(0, steps - 1)) * dt;
    }
    // Drawn last, so that no other draw of a seed depends on it. Spray jobs: 10 % an ensemble of 1 to 3
    // members in either form; calibrations: 1 % one (refused).
    if (chance(kind_ == "spray" ? 0.1 : 0.01)) {
      const long members = kind_ == "spray" ? integer(1, 3) : 2;
      job["ensemble"] = chance(0.5) ? json(members) : json{{"members", members}};
    }
    return job;
  }

 private:
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  double logUniform(double a, double b) { return std::exp(uniform(std::log(a), std::log(b))); }
  long integer(long a, long b) { return std::uniform_int_distribution<long>(a, b)(rng_); }
  bool chance(double p) { return uniform(0.0, 1.0) < p; }
  template <class T>
  const T& pick(const std::vector<T>& v) { return v[std::size_t(integer(0, long(v.size()) - 1))]; }
  static double tanDeg(double d) { return std::tan(d * std::numbers::pi / 180.0); }

  json apparatus() {
    prism_ = kind_ == "database" ? chance(0.7) : chance(0.5);
    if (!prism_) {
      extent_ = {logUniform(0.01, 0.2), logUniform(0.02, 0.3), logUniform(0.005, 0.1)};
      return {{"type", "box"}, {"size", {extent_[0], extent_[1], extent_[2]}}, {"outlet_top", chance(0.7)}};
    }
    const double width = logUniform(0.02, 0.3), slot = width * uniform(0.05, 0.5), angle = uniform(15.0, 75.0);
    const double vTop = 0.5 * (width - slot) * tanDeg(angle);
    const double height = chance(0.03) ? 0.9 * vTop : vTop + logUniform(0.02, 0.4);  // 3 %: V above the top
    extent_ = {width, height, logUniform(0.005, 0.1)};
    slot_ = slot;
    json a = {{"type", "prismatic_spouted_bed"}, {"width", width},     {"depth", extent_[2]},
              {"height", height},                {"inlet_width", slot}, {"prism_angle_deg", angle}};
    if (chance(0.3)) {
      const double thickness = logUniform(5e-4, 4e-3), gap = uniform(0.3, 0.7) * width;
      const double outer = 0.5 * gap + thickness;
      const double below = std::max(0.0, (outer - 0.5 * slot) * tanDeg(angle));
      const double elevation = below + uniform(0.002, 0.03);
      a["draft_plates"] = {{"thickness", thickness},
                           {"gap", gap},
                           {"elevation", elevation},
                           {"height", std::max(0.005, uniform(0.1, 0.5) * (height - elevation))}};
    }
    return a;
  }

  json grid() {
    // 1 to 12 cells along x and z, up to 20 up; at most ~2,000 cells.
    for (int d = 0; d < 3; ++d) {
      const long n = integer(1, d == 1 ? 20 : 12);
      cells_[std::size_t(d)] = extent_[std::size_t(d)] / (double(n) + uniform(-0.2, 0.3) + (n == 1 ? 0.3 : 0.0));
    }
    minCell_ = std::min({cells_[0], cells_[1], cells_[2]});
    if (chance(0.3)) {  // one number for all three (about 1,500 cells); 10 % as large as the largest (may be refused)
      const double c = chance(0.1) ? std::max({cells_[0], cells_[1], cells_[2]})
                                   : std::max(minCell_, std::cbrt(extent_[0] * extent_[1] * extent_[2] / 1500.0));
      cells_ = {c, c, c};
      minCell_ = c;
      return {{"cell_size", c}};
    }
    return {{"cell_size", {cells_[0], cells_[1], cells_[2]}}};
  }

  json particles() {
    cg_ = chance(0.5) ? 1.0 : uniform(1.0, 3.0);
    // Database jobs: parcels of at least a fifth of the smallest cell and a Young's modulus up to 1e8 Pa,
    // so that the DEM step (a fraction of the Rayleigh time) is not below 2e-6 s.
    const bool dem = kind_ == "database";
    diameter_ = minCell_ * (chance(0.03) ? uniform(1.0, 2.0) : uniform(dem ? 0.2 : 0.05, 0.6)) / cg_;
    density_ = logUniform(200.0, 8000.0);
    youngs_ = logUniform(1e5, dem ? 1e8 : 1e9);
    poisson_ = uniform(0.0, 0.49);
    return {{"diameter", diameter_}, {"density", density_}, {"youngs_modulus", youngs_}, {"poisson_ratio", poisson_}};
  }

  json gas() {
    return {{"density", logUniform(0.3, 5.0)},
            {"kinematic_viscosity", logUniform(1e-6, 1e-3)},
            {"cfl", uniform(0.2, 1.0)},
            {"max_time_step", logUniform(2e-5, 1e-3)},
            {"pressure_tolerance", chance(0.03) ? logUniform(1e-13, 1e-10) : logUniform(1e-10, 1e-3)},  // 3 %: refused
            {"smoothing_length", chance(0.4) ? 0.0 : uniform(0.0, 2.0 * minCell_)}};
  }

  json process() {
    const double parcelMass = density_ * std::numbers::pi / 6.0 * std::pow(cg_ * diameter_, 3);
    double bedMass;
    if (kind_ == "database") {
      // 3 %: more than the chamber holds even packed at 0.64 (refused); else 1 - 250 parcels.
      const double chamber = extent_[0] * extent_[1] * extent_[2] * density_;
      bedMass = chance(0.03) ? chamber * uniform(0.7, 10.0) : double(integer(1, 250)) * parcelMass;
    } else {
      bedMass = uniform(0.001, 0.6) * extent_[0] * extent_[1] * extent_[2] * density_;
    }
    // Inlet velocity 0.01 - 100 m/s through the slot (a box has no inlet: refused with the gas).
    const double inlet = prism_ ? slot_ * extent_[2] : extent_[0] * extent_[2];
    // The nozzle's air leaves at 0.1 - 30 m/s (faster jets only shorten the gas step further).
    nozzleDiameter_ = logUniform(1e-4, 1e-2);
    const double nozzle = std::numbers::pi / 4.0 * nozzleDiameter_ * nozzleDiameter_;
    return {{"gas_flow_rate", logUniform(0.01, 100.0) * inlet},
            {"atomisation_flow_rate", chance(0.3) ? 0.0 : logUniform(0.1, 30.0) * nozzle},
            {"bed_mass", bedMass}};
  }

  /// A point inside the bounding box, biased to the lower middle where a bed's nozzle sits.
  std::array<double, 3> lowPoint(double yFraction) {
    return {uniform(-0.3, 0.3) * extent_[0], uniform(0.0, yFraction) * extent_[1], uniform(0.2, 0.8) * extent_[2]};
  }

  json dem() {
    const auto material = rcfd::DemMaterial::make(density_, youngs_, poisson_, 0.5 * cg_ * diameter_, {0.9, 0.75},
                                                  {0.5, 0.24}, {0.06, 0.05});
    const double maxFraction = chance(0.5) ? 0.3 : uniform(0.1, 1.0);
    // 3 %: above the allowed fraction (refused); DEM steps of at least 2e-6 s keep the fill short.
    const double dt = std::max(2e-6, material.rayleighTime() * (chance(0.03) ? 1.5 : uniform(0.05, 1.0)) * maxFraction);
    const long sampleSteps = integer(1, 40), frameSteps = sampleSteps * integer(1, 8);
    const double dtRec = double(frameSteps) * dt, sampleDt = double(sampleSteps) * dt;
    // At most ~0.04 s of coupled time after settling.
    const long frames = integer(3, std::max(3L, std::min(12L, long(0.02 / dtRec))));
    return {{"coarse_graining", cg_},
            {"time_step", dt},
            {"max_rayleigh_fraction", maxFraction},
            {"max_overlap_fraction", uniform(0.001, 0.5)},
            {"coupling_interval", integer(1, 50)},
            {"restitution", {{"particle_particle", uniform(0.1, 1.0)}, {"particle_wall", uniform(0.1, 1.0)}}},
            {"friction", {{"particle_particle", uniform(0.0, 1.0)}, {"particle_wall", uniform(0.0, 1.0)}}},
            {"rolling_friction", {{"particle_particle", uniform(0.0, 0.2)}, {"particle_wall", uniform(0.0, 0.2)}}},
            {"settle_time", uniform(0.0, 0.03)},
            {"ramp_time", chance(0.5) ? 0.0 : uniform(0.0, 0.01)},
            {"warmup", uniform(0.0, 0.01)},
            {"sample_rate", 1.0 / dtRec},
            {"probe_rate", 1.0 / sampleDt},
            {"sample_duration", double(frames) * dtRec},
            {"reference_duration", double(integer(0, std::max(1L, long(0.01 / sampleDt)))) * sampleDt}};
  }

  json spray() {
    const auto nozzle = lowPoint(0.3);
    const double dD = chance(0.03) ? diameter_ * uniform(1.0, 3.0) : diameter_ * logUniform(1e-4, 0.9);
    const double rhoD = logUniform(100.0, 1e4);
    const double massRate = logUniform(1e-8, 1e-2);
    const double droplets = massRate / (rhoD * std::numbers::pi / 6.0 * dD * dD * dD);
    // Up to the droplet rate (3 %: beyond it, refused) and at most 20,000 parcels/s.
    const double parcels = chance(0.03) ? droplets * 10.0 : std::min({droplets, 2e4, logUniform(10.0, 2e4)});
    const double apexY = nozzle[1] * uniform(0.0, 1.0);
    const double yMin = apexY + uniform(0.0, 0.3) * extent_[1];
    const double yMax = std::min(extent_[1], yMin + uniform(0.02, 0.6) * extent_[1]);
    return {{"nozzle_position", {nozzle[0], nozzle[1], nozzle[2]}},
            {"nozzle_diameter", nozzleDiameter_},
            {"cone_half_angle_deg", uniform(1.0, 89.0)},
            {"mass_rate", massRate},
            {"droplet_diameter", dD},
            {"droplet_density", rhoD},
            {"parcels_per_s", std::max(parcels, 1e-3)},
            {"deposition_model", chance(0.5) ? "exponential" : "linear_clipped"},
            {"spray_zone",
             {{"apex", {nozzle[0], apexY, nozzle[2]}},
              {"half_angle_deg", uniform(5.0, 60.0)},
              {"y_min", yMin},
              {"y_max", yMax}}}};
  }

  json probes() {
    json p = json::array();
    const long n = kind_ == "calibration" ? integer(chance(0.05) ? 0 : 1, 3) : integer(0, 3);
    for (long i = 0; i < n; ++i) {
      const auto q = lowPoint(0.8);
      p.push_back({{"name", "p" + std::to_string(i)}, {"position", {q[0], q[1], q[2]}}});
    }
    return p;
  }

  json databaseEffects() {
    json e = json::array();
    const bool gas = chance(prism_ ? 0.6 : 0.1);
    if (gas) {
      e.push_back("gas");
      if (chance(0.8)) e.push_back("drag");
      if (chance(0.5)) e.push_back("smoothing");
    }
    if (chance(0.5)) e.push_back("rolling_friction");
    if (chance(0.15)) {  // the reference coverage (and with it the tracer effects' needs)
      for (const char* name : {"transport", "tracer_volume_fraction", "spray", "deposition", "coverage"}) e.push_back(name);
    } else if (chance(0.1)) {
      for (const char* name : {"transport", "tracer_volume_fraction", "velocity_streams"}) e.push_back(name);
    }
    return e;
  }

  json tracerEffects() {
    json e = json::array();
    auto add = [&](const char* name, double p) {
      if (chance(p)) e.push_back(name);
    };
    const bool strict = chance(0.95);  // 5 %: dependencies left to chance (refused naming the effect)
    add("transport", strict ? 1.0 : 0.8);
    add("walls", 0.9);
    add("free_flight", 0.4);
    const double r = uniform(0.0, 1.0);
    const bool tvf = r < 0.75 || !strict;
    if (r < 0.35) e.push_back("fluctuation");
    else if (r < 0.6) e.push_back("directed_relaxation");
    if (chance(0.2)) e.push_back("langevin_velocity"), spread_ = true;
    if (chance(0.15)) e.push_back("velocity_streams"), spread_ = true;
    const bool spray = chance(0.6);
    if (tvf || spread_ || spray || strict) add("tracer_volume_fraction", strict ? 1.0 : 0.7);
    add("probes", 0.5);
    add("residence_time", 0.6);
    add("field_average", 0.4);
    if (spray) {
      e.push_back("spray");
      if (chance(0.8)) {
        e.push_back("deposition");
        if (chance(0.8)) e.push_back("coverage");
        add("deposition_maps", 0.4);
      }
    }
    if (chance(0.03)) spread_ = false;  // 3 %: a Langevin or two-stream run on a database without the spread
    return e;
  }

  json rcfd(double dtRec) {
    json r = {{"dt", dtRec / double(integer(1, 4))},
              {"tracers", long(logUniform(1.0, 3000.0))},
              {"d0", chance(0.1) ? 0.0 : logUniform(1e-7, 0.1)},
              {"u_fluc_max", logUniform(0.01, 10.0)},
              {"langevin_time", uniform(1e-3, 10.0)},
              {"free_flight_alpha", uniform(0.0, 0.99)},
              {"fluctuation_model", chance(0.5) ? "lichtenegger_pirker" : "cfdem"},
              {"max_courant", logUniform(0.1, 10.0)},
              {"integrator", chance(0.7) ? "midpoint" : "euler"}};
    frames_ = integer(3, 30);
    const double frameBytes = double(cells()) * (spread_ ? 17.0 : 7.0) * 4.0;
    if (chance(0.3)) r["frame_cache_bytes"] = long(frameBytes * (chance(0.1) ? 0.5 : uniform(1.0, 5.0)));
    const double lo = uniform(0.01, 0.5);
    if (chance(0.6)) {
      r["path"] = {{"type", "paper"}, {"min_sequence_fraction", lo}, {"max_sequence_fraction", std::min(1.0, lo * uniform(1.0, 3.0))}};
    } else {
      r["path"] = {{"type", "markov"},
                   {"min_sequence_fraction", lo},
                   {"max_sequence_fraction", std::min(1.0, lo * uniform(1.0, 3.0))},
                   {"min_sequence_frames", integer(1, 10)},
                   {"correlation_window", integer(0, 10)}};
    }
    return r;
  }

  long cells() const {
    long n = 1;
    for (int d = 0; d < 3; ++d) n *= std::max(1L, std::lround(extent_[std::size_t(d)] / cells_[std::size_t(d)]));
    return n;
  }

  /// A database of the scene's grid: smooth random waves of alpha_P in [0, a_max] (a_max sometimes 0 or
  /// 0.74), velocities up to 0.001-50 m/s (particles) and 0.001-100 m/s (gas), moving with the frames.
  void writeDatabase(const json& scene, double dtRec) {
    SceneGrid g;
    try {
      g = sceneGrid(scene);
    } catch (const rcfd::InputError&) {
      return;  // a scene the schema or its rules refuse: the job is refused before it opens a database
    }
    const rcfd::CartesianGrid cellGrid = g.grid;
    const double aMax = chance(0.1) ? 0.0 : chance(0.1) ? 0.74 : uniform(0.05, 0.74);
    const double up = logUniform(1e-3, 50.0), ug = logUniform(1e-3, 100.0);
    std::array<double, 12> k;
    for (double& v : k) v = uniform(-300.0, 300.0);
    const double noise = chance(0.3) ? uniform(0.0, 1.0) : 0.0;
    const std::uint64_t noiseSeed = rng_();
    const bool spread = spread_;
    auto fill = [=, grid = cellGrid](int n, double t, rcfd::FieldFrame& f) {
      std::mt19937_64 local(noiseSeed + std::uint64_t(n));
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      if (spread) {
        f.up_fraction.assign(f.alpha_p.size(), 0.0f);
        f.u_p_up.assign(f.u_p.size(), 0.0f), f.u_p_down.assign(f.u_p.size(), 0.0f), f.u_p_variance.assign(f.u_p.size(), 0.0f);
      }
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
        const auto ijk = grid.cellIjk(c);
        const Eigen::Vector3d p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
        const double w = std::sin(k[0] * p.x() + k[1] * p.y() + k[2] * p.z() + 7.0 * t);
        const double a = std::clamp(0.5 * aMax * (1.0 + (1.0 - noise) * w + noise * u(local)), 0.0, aMax);
        f.alpha_p[std::size_t(c)] = float(a);
        for (int d = 0; d < 3; ++d) {
          const double s = std::sin(k[std::size_t(3 + d)] * p[(d + 1) % 3] + k[std::size_t(6 + d)] * t + n);
          f.u_p[3 * c + d] = float(up * ((1.0 - noise) * s + noise * u(local)));
          f.u_g[3 * c + d] = float(ug * std::cos(k[std::size_t(9 + d)] * p[d] + 3.0 * t));
        }
        if (spread) {
          // Up and down streams about the mean, in the share up_fraction, with a variance >= 0.
          const double share = a > 0.0 ? 0.5 * (1.0 + 0.9 * std::sin(double(c + n))) : 0.0;
          f.up_fraction[std::size_t(c)] = float(share);
          for (int d = 0; d < 3; ++d) {
            const double mean = f.u_p[3 * c + d], delta = d == 1 ? 0.3 * up : 0.0;
            f.u_p_up[3 * c + d] = float(mean + (1.0 - share) * delta);
            f.u_p_down[3 * c + d] = float(mean - share * delta);
            f.u_p_variance[3 * c + d] = float(0.05 * up * up * (1.0 + std::sin(double(3 * c + d))));
          }
        }
      }
    };
    rcfd::FieldDatabaseWriterOptions options;
    options.velocitySpread = spread;
    writeAnalyticDatabase((dir_ / "db.h5").string(), cellGrid, g.fluid, dtRec, int(frames_), fill, scene.dump(), options);
  }

  std::mt19937_64 rng_;
  std::uint64_t seed_;
  fs::path dir_;
  std::string kind_;
  bool prism_ = false, spread_ = false;
  std::array<double, 3> extent_{}, cells_{};
  double slot_ = 0.0, minCell_ = 0.0, nozzleDiameter_ = 1e-3, cg_ = 1.0, diameter_ = 0.0, density_ = 0.0, youngs_ = 0.0, poisson_ = 0.0;
  long frames_ = 3;
};

struct Tally {
  long scenes = 0;
  std::map<std::string, long> ended;  ///< "spray: exit 0", "database: exit 2 /scene/process/bed_mass", ...
  std::map<std::string, std::string> example;  ///< per way of ending: the first message and its seed
  std::vector<std::string> failures;
  double slowest = 0.0;
  std::uint64_t slowestSeed = 0;
};

/// The pointer of the first violation of an exit-2 message ("/scene/dem/time_step").
std::string firstPointer(const std::string& text) {
  static const std::regex pointer(R"((/[A-Za-z_@0-9]+(/[A-Za-z_@0-9]+)*))");
  const auto at = text.find("error: invalid input: ");
  std::smatch m;
  const std::string rest = text.substr(at == std::string::npos ? 0 : at + 22);
  const auto colon = rest.find(": ");  // after the source (a path, which has slashes of its own)
  const std::string after = colon == std::string::npos ? rest : rest.substr(colon);
  return std::regex_search(after, m, pointer) ? m.str(1) : "?";
}

}  // namespace

TEST(PropertyJobs, RandomValidScenesEndInSuccessOrAClearInputErrorWithinTheTimeBound) {
  std::uint64_t first = 34;
  if (const char* s = std::getenv("RCFD_PROPERTY_SEED"); s && *s) {
    first = std::string(s) == "random" ? std::random_device{}() : std::strtoull(s, nullptr, 10);
  }
  const long scenes = envLong("RCFD_PROPERTY_SCENES", kDefaultScenes);
  const double bound = double(envLong("RCFD_PROPERTY_TIME_BOUND", long(kDefaultTimeBound)));
  const bool keep = envLong("RCFD_PROPERTY_KEEP", 0) != 0;
  std::cerr << "property test: " << scenes << " scenes from seed " << first << ", time bound " << bound << " s\n";
  Tally tally;
  const auto start = std::chrono::steady_clock::now();
  for (long i = 0; i < scenes; ++i) {
    const std::uint64_t seed = first + std::uint64_t(i);
    const fs::path dir = caseDirectory("property-" + std::to_string(seed));
    json job;
    std::string problem;
    Outcome o;
    try {
      job = JobGenerator(seed, dir).make();
      const int threads = (seed % 3 == 0) ? 2 : 1;
      o = runJob(job, dir, bound, threads);
      // The one documented ending besides exit 0 and 2: a gas solve that does not reach the scene's
      // pressure tolerance (tolerances near the round-off floor of strongly anisotropic cells).
      problem = o.exitCode == 3 ? gasNonConvergenceProblem(o, dir) : outcomeProblem(o, job, dir);
    } catch (const std::exception& e) {
      problem = std::string("the generator failed: ") + e.what();
    }
    const std::string kind = job.is_object() ? job.value("kind", std::string("?")) : "?";
    ++tally.scenes;
    if (o.seconds > tally.slowest) tally.slowest = o.seconds, tally.slowestSeed = seed;
    if (problem.empty()) {
      const std::string way = kind + ": exit " + std::to_string(o.exitCode) +
                              (o.exitCode == 2   ? " " + firstPointer(o.stderrText)
                               : o.exitCode == 3 ? std::string(" gas solve did not converge")
                                                 : std::string());
      if (++tally.ended[way] == 1 && o.exitCode != 0) {
        const auto at = o.stderrText.find("error: ");
        tally.example[way] = "seed " + std::to_string(seed) + ": " + o.stderrText.substr(at, 400);
      }
      if (!keep) fs::remove_all(dir);
    } else {
      tally.failures.push_back("seed " + std::to_string(seed) + " (" + kind + ", " + dir.string() + "): " + problem);
      ADD_FAILURE() << "seed " << seed << ": reproduce with RCFD_PROPERTY_SEED=" << seed
                    << " RCFD_PROPERTY_SCENES=1 RCFD_PROPERTY_KEEP=1; job " << (dir / "job.json").string() << "\n"
                    << problem;
    }
    if ((i + 1) % 100 == 0 || i + 1 == scenes) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::cerr << "property test: " << (i + 1) << " of " << scenes << " scenes, " << tally.failures.size()
                << " failed, " << wall << " s\n";
    }
  }
  long succeeded = 0;
  std::cerr << "property test: how the " << tally.scenes << " scenes ended (slowest " << tally.slowest << " s, seed "
            << tally.slowestSeed << "):\n";
  for (const auto& [what, count] : tally.ended) {
    std::cerr << "  " << count << "  " << what << "\n";
    if (tally.example.count(what)) std::cerr << "        " << tally.example[what] << "\n";
    if (what.find("exit 0") != std::string::npos) succeeded += count;
  }
  // Most scenes must run to the end: a generator that only produced refused scenes would prove nothing.
  if (scenes >= 50) {
    EXPECT_GE(succeeded, scenes / 2) << "too few scenes ran to the end";
  }
}
