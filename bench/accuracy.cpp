// rcfd-bench accuracy: what accuracy costs in time, on one scene and its database. A ladder of rCFD
// settings, each knob varied alone from the scene's own settings, is run as spray jobs over the same
// simulated time with several seeds (each its own recurrence path and tracer placement); every run's
// wall time is set against its errors:
//   - against the full simulation's reference period (the database's /reference/): spray-zone holdup,
//     mean stay, crossing rate and the KS distance of the stays, at a common resolution
//     (summary.json's stay_comparison);
//   - against the recurrence fields: the time-averaged alpha_P of the tracers (field_average);
//   - against the finest setting (most tracers, smallest step): the distribution of droplets per
//     particle (KS distance, mean, p10, p90) and the overspray, with the finest setting's own seed
//     spread beside them, so that statistical and systematic error are told apart.
// Knobs: tracer count, rCFD time step, integrator, tracer motion model, velocity interpolation, D0, free
// flight, sub-steps, and the database's sampling rate and length (subsampled copies of the database: every k-th frame, the
// first frames), with the frames between two held or blended (rcfd.frame_interpolation). The database's own cost (cell size, coarse graining) is a database job per setting and
// is not part of this ladder (docs/accuracy.md).
// Writes OUT/accuracy.json (every run), OUT/accuracy.md (tables), OUT/accuracy-stays.svg and
// OUT/accuracy-coverage.svg (error against wall time, one curve per knob, the Pareto front marked).
// Resumable: runs whose summary.json exists are read, not rerun.
// RCFD_BENCH_SCENE (default examples/quick.json), RCFD_BENCH_DATABASE (a database job's database.h5 for
// that scene; default: the scene's database job is run into OUT/database first), RCFD_BENCH_OUT (default
// bench-out/accuracy-SCENE), RCFD_BENCH_SEEDS (default 3, --quick 2), RCFD_BENCH_DURATION (simulated
// seconds per run; default 10, --quick 5).
#include <hdf5.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "BenchRegistry.hpp"
#include "analysis/KsDistance.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "core/Svg.hpp"
#include "fields/FieldDatabase.hpp"
#include "jobs/JobRunner.hpp"
#include "scene/SceneLoader.hpp"

namespace rcfd::bench {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string envOr(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

json readJson(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw RunError("cannot read " + path.string());
  return json::parse(in);
}

/// User and system time of this process, all threads [s].
double cpuSecondsOfProcess() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// One rung of the ladder: a knob, the value it takes, and how the job differs from the baseline.
struct Setting {
  std::string knob;     ///< "tracers", "dt", ...; "baseline" for the scene's own settings
  std::string label;    ///< the knob's value as shown in tables
  json patch;           ///< merged into the job's scene_patch
  std::string database; ///< database file of the run (a subsampled copy for the database knobs)
  std::string id;       ///< directory name under OUT/runs
};

/// The statistics of one run that the errors are computed from.
struct RunResult {
  double wallSeconds = 0.0;      ///< the job's wall time (database load included) [s]
  double cpuSeconds = NAN;       ///< CPU time of all its threads (bench-cost.json; a loaded machine's fair cost) [s]
  double holdupError = NAN, stayError = NAN, crossingError = NAN, staysKs = NAN;
  double fieldRms = NAN;         ///< RMS of the time-averaged alpha_P, tracers against frames [-]
  double overspray = NAN;
  std::vector<double> droplets;  ///< droplets per particle, one value per tracer
};

double numberOr(const json& j, const char* key) {
  return j.contains(key) && j.at(key).is_number() ? j.at(key).get<double>() : NAN;
}

RunResult readRun(const fs::path& dir, double referenceHoldup) {
  const json s = readJson(dir / "summary.json");
  RunResult r;
  r.wallSeconds = s.at("wall_time_s").get<double>();
  if (s.contains("stay_comparison")) {
    const json& c = s.at("stay_comparison");
    r.stayError = numberOr(c, "mean_relative_error");
    r.crossingError = numberOr(c, "crossing_rate_relative_error");
    r.staysKs = numberOr(c, "ks_distance");
  }
  if (s.contains("holdup") && referenceHoldup > 0.0)  // both in real particles
    r.holdupError = numberOr(s.at("holdup"), "mean") / referenceHoldup - 1.0;
  if (s.contains("field_average")) r.fieldRms = numberOr(s.at("field_average"), "rms_difference");
  r.overspray = numberOr(s, "overspray_fraction");
  if (fs::exists(dir / "bench-cost.json")) r.cpuSeconds = numberOr(readJson(dir / "bench-cost.json"), "cpu_s");
  h5::File f((dir / "result.h5").string(), h5::File::Mode::ReadOnly);
  if (f.exists("/coverage/droplets_per_particle")) r.droplets = f.readDoubles("/coverage/droplets_per_particle");
  return r;
}

/// A copy of `source` with every `stride`-th frame of its first `frames` frames (its sampling rate
/// divided by stride, its length cut) and its /reference/ group: the database a shorter or sparser
/// sampling of the same full simulation would have written.
void writeSubsampledDatabase(const std::string& source, const std::string& target, int stride, int frames) {
  if (fs::exists(target)) return;
  FrameStorage storage;
  storage.cacheBytes = std::int64_t(1) << 28;
  storage.velocitySpread = storage.velocitySpreadIfPresent = true;  // the copy keeps what the source has
  auto db = FieldDatabase::open(source, storage);
  const std::string partial = target + ".partial";
  {
    FieldDatabaseWriterOptions options;
    options.velocitySpread = db->hasVelocitySpread();
    FieldDatabaseWriter writer(partial, db->grid(), db->fluidFraction(), db->dtRec() * stride, db->sceneJson(),
                               options);
    for (int i = 0; i < std::min(frames, db->frameCount()); i += stride) writer.append(*db->frame(i));
    writer.close();
  }
  {
    h5::File from(source, h5::File::Mode::ReadOnly);
    h5::File to(partial, h5::File::Mode::ReadWrite);
    if (from.exists("/reference") &&
        H5Ocopy(from.id(), "/reference", to.id(), "/reference", H5P_DEFAULT, H5P_DEFAULT) < 0)
      throw RunError("cannot copy /reference of " + source + " into " + partial);
  }
  fs::rename(partial, target);
}

/// The scene's effects with a tracer motion model selected (the models of scripts/model-effects.jq).
json effectsOfModel(json effects, const std::string& model) {
  json out = json::array();
  for (const auto& e : effects) {
    const std::string name = e.get<std::string>();
    if (name == "langevin_velocity" || name == "velocity_streams") continue;
    if (name == "fluctuation" || name == "directed_relaxation") {
      out.push_back(model == "mean" ? "fluctuation" : "directed_relaxation");
      if (model == "langevin") out.push_back("langevin_velocity");
      continue;
    }
    out.push_back(name);
  }
  return out;
}

json withoutEffect(const json& effects, const std::string& name) {
  json out = json::array();
  for (const auto& e : effects)
    if (e.get<std::string>() != name) out.push_back(e);
  return out;
}

std::string formatNumber(double v, int precision = 3) {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

std::string percent(double v) {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream s;
  s << std::showpos << std::fixed << std::setprecision(1) << 100.0 * v << " %";
  return s.str();
}

struct Spread {
  double mean = NAN, sd = NAN;
};

Spread spreadOf(const std::vector<double>& values) {
  std::vector<double> v;
  for (double x : values)
    if (std::isfinite(x)) v.push_back(x);
  Spread s;
  if (v.empty()) return s;
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / double(v.size());
  if (v.size() > 1) {
    double q = 0.0;
    for (double x : v) q += (x - s.mean) * (x - s.mean);
    s.sd = std::sqrt(q / double(v.size() - 1));
  }
  return s;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const auto lo = std::size_t(std::floor(pos));
  const auto hi = std::min(v.size() - 1, lo + 1);
  return v[lo] + (pos - double(lo)) * (v[hi] - v[lo]);
}

double meanOf(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? NAN : s / double(v.size());
}

/// A setting's runs summarised: wall time and every error as mean and seed spread.
struct Row {
  /// What a run costs on the plots: its CPU time where measured (fair on a shared machine), else its wall time.
  double cost() const { return std::isfinite(cpu.mean) ? cpu.mean : wall.mean; }
  Setting setting;
  Spread wall, cpu, holdup, stay, crossing, staysKs, fieldRms, coverageKs, coverageMean, p10, p90, overspray;
  double staysError() const {  // the figure the stays plot shows: the largest of the four
    return std::max({std::fabs(stay.mean), std::fabs(crossing.mean), std::fabs(holdup.mean), staysKs.mean},
                    [](double a, double b) { return (std::isfinite(a) ? a : -1.0) < (std::isfinite(b) ? b : -1.0); });
  }
};

/// Indices of the rows on the Pareto front of (wall time, error): no other row is both faster and closer.
std::vector<std::size_t> paretoFront(const std::vector<Row>& rows, double (*error)(const Row&)) {
  std::vector<std::size_t> front;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double wi = rows[i].cost(), ei = error(rows[i]);
    if (!std::isfinite(ei)) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < rows.size() && !dominated; ++j) {
      const double wj = rows[j].cost(), ej = error(rows[j]);
      if (j != i && std::isfinite(ej) && wj <= wi && ej <= ei && (wj < wi || ej < ei)) dominated = true;
    }
    if (!dominated) front.push_back(i);
  }
  return front;
}

/// Error against wall time on log-log axes: one polyline per knob (rungs in ladder order), the
/// baseline in black, the Pareto front circled.
void plotErrorAgainstTime(const std::vector<Row>& rows, double (*error)(const Row&), const std::string& title,
                          const std::string& ylabel, const std::string& path) {
  double wmin = 1e300, wmax = 0.0, emin = 1e300, emax = 0.0;
  for (const Row& r : rows) {
    const double e = error(r);
    if (!std::isfinite(e) || !(e > 0.0) || !(r.cost() > 0.0)) continue;
    wmin = std::min(wmin, r.cost()), wmax = std::max(wmax, r.cost());
    emin = std::min(emin, e), emax = std::max(emax, e);
  }
  if (!(wmax > 0.0)) return;
  const double x0 = std::floor(std::log10(wmin) * 4) / 4, x1 = std::ceil(std::log10(wmax) * 4) / 4 + 0.25;
  const double y0 = std::floor(std::log10(emin) * 4) / 4, y1 = std::ceil(std::log10(emax) * 4) / 4 + 0.1;
  SvgDocument svg(x0, x1, y0, y1, 720, 480, 70);
  svg.axes("log10 CPU time per run [s]", ylabel);
  svg.textPx(360, 24, title, 14, "middle");
  static const char* colours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                  "#8c564b", "#e377c2", "#17becf", "#bcbd22"};
  std::map<std::string, std::vector<std::array<double, 2>>> curves;
  std::vector<std::string> order;
  for (const Row& r : rows) {
    const double e = error(r);
    if (!std::isfinite(e) || !(e > 0.0) || r.setting.knob == "baseline") continue;
    if (!curves.count(r.setting.knob)) order.push_back(r.setting.knob);
    curves[r.setting.knob].push_back({std::log10(r.cost()), std::log10(e)});
  }
  std::size_t k = 0;
  for (const auto& knob : order) {
    const std::string colour = colours[k % 9];
    svg.polyline(curves[knob], colour, 1.5);
    for (const auto& p : curves[knob]) svg.circle(p[0], p[1], 3, colour);
    svg.text(x0 + 0.02 * (x1 - x0), y1 - (0.05 + 0.05 * double(k)) * (y1 - y0), knob, 12, "start", colour);
    ++k;
  }
  for (const Row& r : rows)
    if (r.setting.knob == "baseline" && std::isfinite(error(r)) && error(r) > 0.0)
      svg.circle(std::log10(r.cost()), std::log10(error(r)), 5, "#000");
  // The Pareto front: a dashed staircase through the settings no other beats in both time and error.
  std::vector<std::size_t> front = paretoFront(rows, error);
  std::sort(front.begin(), front.end(), [&](std::size_t a, std::size_t b) { return rows[a].cost() < rows[b].cost(); });
  for (std::size_t n = 0; n < front.size(); ++n) {
    const double x = std::log10(rows[front[n]].cost()), y = std::log10(error(rows[front[n]]));
    if (n + 1 < front.size()) {
      const double xn = std::log10(rows[front[n + 1]].cost()), yn = std::log10(error(rows[front[n + 1]]));
      svg.line(x, y, xn, y, "#000", 1.0, "4 3");
      svg.line(xn, y, xn, yn, "#000", 1.0, "4 3");
    }
    svg.text(x, y, "  " + rows[front[n]].setting.knob + " " + rows[front[n]].setting.label, 10, "start");
  }
  svg.save(path);
}

json runAccuracy(const Options& options) {
  const std::string scenePath = envOr("RCFD_BENCH_SCENE", "examples/quick.json");
  const json sceneDoc = readJson(scenePath);
  const std::string sceneName = sceneDoc.value("name", fs::path(scenePath).stem().string());
  const fs::path out = fs::absolute(envOr("RCFD_BENCH_OUT", "bench-out/accuracy-" + sceneName));
  const int seeds = std::stoi(envOr("RCFD_BENCH_SEEDS", options.quick ? "2" : "3"));
  const double duration = std::stod(envOr("RCFD_BENCH_DURATION", options.quick ? "5" : "10"));
  fs::create_directories(out / "runs");
  const std::string sceneAbs = fs::absolute(scenePath).string();

  // The database: given, or the scene's own database job run here first (resumable).
  std::string database = envOr("RCFD_BENCH_DATABASE", "");
  double databaseWall = NAN;
  if (database.empty()) {
    const fs::path dir = out / "database";
    if (!fs::exists(dir / "summary.json")) {
      std::cerr << "accuracy: the scene's database job into " << dir.string() << " (RCFD_BENCH_DATABASE skips it)\n";
      const json job = {{"kind", "database"}, {"scene_file", sceneAbs}, {"seed", 1}, {"checkpoint_interval", 0.5}};
      RunOptions ro;
      ro.outDir = dir.string();
      runJob(loadJob(job, "accuracy database job"), ro);
    }
    database = (dir / "database.h5").string();
    databaseWall = readJson(dir / "summary.json").at("wall_time_s").get<double>();
  }
  database = fs::absolute(database).string();
  int frames = 0;
  double dtRec = 0.0;
  {
    auto db = FieldDatabase::open(database, FrameStorage{std::int64_t(1) << 26});
    frames = db->frameCount();
    dtRec = db->dtRec();
  }
  double referenceHoldup = NAN;  // the full simulation's mean spray-zone holdup [particles]
  {
    h5::File f(database, h5::File::Mode::ReadOnly);
    if (f.exists("/reference/holdup/particles")) referenceHoldup = meanOf(f.readDoubles("/reference/holdup/particles"));
  }

  const json& rcfd = sceneDoc.at("rcfd");
  const json effects = sceneDoc.at("effects");
  const long particles = std::lround(sceneDoc.at("process").at("bed_mass").get<double>() /
                                     (sceneDoc.at("particles").at("density").get<double>() * M_PI / 6.0 *
                                      std::pow(sceneDoc.at("particles").at("diameter").get<double>(), 3)));
  const int baseTracers = rcfd.value("tracers", 20000);
  const double baseDt = rcfd.value("dt", 0.005);

  std::vector<Setting> ladder;
  auto add = [&](std::string knob, std::string label, json patch, std::string db = "") {
    Setting s{std::move(knob), std::move(label), std::move(patch), db.empty() ? database : db, ""};
    s.id = s.knob + "-" + s.label;
    ladder.push_back(std::move(s));
  };
  add("baseline", "scene", json::object());
  const std::vector<long> tracerCounts = options.quick ? std::vector<long>{1000, 5000, particles}
                                                       : std::vector<long>{1000, 5000, 50000, particles};
  for (long n : tracerCounts)
    if (n != baseTracers) add("tracers", std::to_string(n), {{"rcfd", {{"tracers", n}}}});
  // rCFD steps divide the database's interval (rcfd.dt = dt_rec / k); longer steps than dt_rec come with
  // the sparser databases of the "sampling" knob.
  for (int k : {2, 5}) {
    const double dt = dtRec / k;
    if (std::fabs(dt - baseDt) > 1e-12) add("dt", formatNumber(dt * 1e3) + "ms", {{"rcfd", {{"dt", dt}}}});
  }
  add("integrator", rcfd.value("integrator", "midpoint") == "euler" ? "midpoint" : "euler",
      {{"rcfd", {{"integrator", rcfd.value("integrator", "midpoint") == "euler" ? "midpoint" : "euler"}}}});
  for (const std::string model : {"mean", "relax", "langevin"})
    if (effectsOfModel(effects, model) != effects) add("model", model, {{"effects", effectsOfModel(effects, model)}});
  // u_P^rec between cell centres: the scene's interpolation against the other one.
  const std::string interpolation = rcfd.value("velocity_interpolation", "trilinear");
  const std::string otherInterpolation = interpolation == "mass_weighted" ? "trilinear" : "mass_weighted";
  add("velocity_interpolation", otherInterpolation, {{"rcfd", {{"velocity_interpolation", otherInterpolation}}}});
  for (double d0 : options.quick ? std::vector<double>{0.0, 1e-3} : std::vector<double>{0.0, 1e-4, 1e-3, 1e-2})
    if (std::fabs(d0 - rcfd.value("d0", 0.0)) > 1e-15) add("d0", formatNumber(d0), {{"rcfd", {{"d0", d0}}}});
  if (withoutEffect(effects, "free_flight") != effects)
    add("free_flight", "off", {{"effects", withoutEffect(effects, "free_flight")}});
  add("sub_steps", "off", {{"rcfd", {{"max_courant", 1e6}}}});
  const std::string rule = rcfd.value("frame_interpolation", "hold");
  const std::string otherRule = rule == "linear" ? "hold" : "linear";
  for (int stride : {2, 4, 10}) {
    const std::string db = (out / ("database-every" + std::to_string(stride) + ".h5")).string();
    writeSubsampledDatabase(database, db, stride, frames);
    const std::string rate = formatNumber(1.0 / (dtRec * stride)) + "Hz";
    add("sampling", rate, json::object(), db);
    // Between two sparse frames the scene's rule against the other one, at the scene's step.
    add("between_frames", otherRule + "-" + rate, {{"rcfd", {{"frame_interpolation", otherRule}}}}, db);
    // The longest rCFD step a database allows is its interval: twice the scene's step on every second
    // frame (the step and the sampling rate change together; compare with that sampling row).
    if (stride == 2 && std::fabs(dtRec * stride - baseDt) > 1e-12)
      add("dt", formatNumber(dtRec * stride * 1e3) + "ms", {{"rcfd", {{"dt", dtRec * stride}}}}, db);
  }
  for (int part : {2, 4}) {
    const int n = frames / part;
    const std::string db = (out / ("database-first" + std::to_string(n) + ".h5")).string();
    writeSubsampledDatabase(database, db, 1, n);
    add("length", formatNumber(n * dtRec) + "s", json::object(), db);
  }
  // The finest setting: the coverage reference (most tracers, smallest step of the ladder).
  add("finest", "reference", {{"rcfd", {{"tracers", std::max<long>(particles, baseTracers)}, {"dt", dtRec / 5}}}});

  std::vector<Row> rows;
  std::map<std::string, std::vector<RunResult>> results;
  const auto start = std::chrono::steady_clock::now();
  std::size_t done = 0;
  std::map<std::string, std::string> failures;  // setting id -> why its runs could not be made
  for (const Setting& s : ladder) {
    for (int seed = 1; seed <= seeds && !failures.count(s.id); ++seed) {
      const fs::path dir = out / "runs" / (s.id + "-s" + std::to_string(seed));
      if (!fs::exists(dir / "summary.json")) {
        const json job = {{"kind", "spray"}, {"scene_file", sceneAbs}, {"scene_patch", s.patch},
                          {"database", s.database}, {"duration", duration}, {"seed", seed},
                          {"checkpoint_interval", duration}};
        RunOptions ro;
        ro.outDir = dir.string();
        ro.progressInterval = 1e9;
        try {
          const double cpuBefore = cpuSecondsOfProcess();
          runJob(loadJob(job, "accuracy run " + dir.filename().string()), ro);
          std::ofstream(dir / "bench-cost.json") << json{{"cpu_s", cpuSecondsOfProcess() - cpuBefore}}.dump() << "\n";
        } catch (const std::exception& e) {  // InputError or RunError: the setting is reported, not run
          failures[s.id] = e.what();
          std::cerr << "accuracy: " << s.knob << " " << s.label << " failed: " << e.what() << "\n";
          continue;
        }
      }
      results[s.id].push_back(readRun(dir, referenceHoldup));
      ++done;
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::cerr << "accuracy: " << done << " of " << ladder.size() * std::size_t(seeds) << " runs (" << s.knob << " "
                << s.label << ", seed " << seed << "), " << std::fixed << std::setprecision(0) << wall << " s\n"
                << std::defaultfloat;
    }
  }

  // Coverage reference: the finest setting's runs pooled; its own seed spread is the statistical floor.
  std::vector<double> finestDroplets;
  std::vector<double> finestOverspray;
  for (const RunResult& r : results.at("finest-reference")) {
    finestDroplets.insert(finestDroplets.end(), r.droplets.begin(), r.droplets.end());
    finestOverspray.push_back(r.overspray);
  }
  const double refMean = meanOf(finestDroplets), refP10 = quantile(finestDroplets, 0.1),
               refP90 = quantile(finestDroplets, 0.9), refOverspray = meanOf(finestOverspray);
  auto relative = [](double v, double ref) { return ref != 0.0 && std::isfinite(ref) ? v / ref - 1.0 : NAN; };

  json runsJson = json::array();
  if (failures.count("finest-reference")) throw RunError("the finest setting failed: " + failures.at("finest-reference"));
  for (const Setting& s : ladder) {
    if (failures.count(s.id)) continue;
    Row row;
    row.setting = s;
    std::vector<double> wall, cpu, holdup, stay, crossing, ks, field, cks, cmean, p10, p90, overspray;
    const auto& rs = results.at(s.id);
    for (std::size_t i = 0; i < rs.size(); ++i) {
      const RunResult& r = rs[i];
      wall.push_back(r.wallSeconds), cpu.push_back(r.cpuSeconds);
      holdup.push_back(r.holdupError), stay.push_back(r.stayError), crossing.push_back(r.crossingError);
      ks.push_back(r.staysKs), field.push_back(r.fieldRms);
      // Against the finest setting: its other seeds' pooled sample when this is the finest itself.
      std::vector<double> ref;
      if (s.id == "finest-reference") {
        for (std::size_t j = 0; j < rs.size(); ++j)
          if (j != i) ref.insert(ref.end(), rs[j].droplets.begin(), rs[j].droplets.end());
      } else {
        ref = finestDroplets;
      }
      const double m = meanOf(r.droplets);
      cks.push_back(!r.droplets.empty() && !ref.empty() ? analysis::ksDistance(r.droplets, ref) : NAN);
      cmean.push_back(relative(m, refMean));
      // p10 and p90 as differences over the reference mean: a short spray's p10 is 0 droplets.
      p10.push_back((quantile(r.droplets, 0.1) - refP10) / refMean);
      p90.push_back((quantile(r.droplets, 0.9) - refP90) / refMean);
      overspray.push_back(r.overspray - refOverspray);
      runsJson.push_back({{"knob", s.knob}, {"value", s.label}, {"seed", i + 1}, {"wall_s", r.wallSeconds},
                          {"cpu_s", r.cpuSeconds}, {"holdup_error", r.holdupError},
                          {"mean_stay_error", r.stayError}, {"crossing_rate_error", r.crossingError},
                          {"stays_ks", r.staysKs}, {"field_rms", r.fieldRms}, {"coverage_ks", cks.back()},
                          {"coverage_mean_error", cmean.back()}, {"coverage_p10_error", p10.back()},
                          {"coverage_p90_error", p90.back()}, {"overspray", r.overspray}});
    }
    row.wall = spreadOf(wall), row.cpu = spreadOf(cpu), row.holdup = spreadOf(holdup);
    row.stay = spreadOf(stay), row.crossing = spreadOf(crossing), row.staysKs = spreadOf(ks);
    row.fieldRms = spreadOf(field), row.coverageKs = spreadOf(cks), row.coverageMean = spreadOf(cmean);
    row.p10 = spreadOf(p10), row.p90 = spreadOf(p90), row.overspray = spreadOf(overspray);
    rows.push_back(row);
  }

  // The table: one row per setting, mean (seed spread) of each figure.
  auto cell = [](const Spread& s, bool pct) {
    if (!std::isfinite(s.mean)) return std::string("n/a");
    std::string text = pct ? percent(s.mean) : formatNumber(s.mean);
    if (std::isfinite(s.sd)) text += " (" + (pct ? formatNumber(100.0 * s.sd, 2) + " %" : formatNumber(s.sd, 2)) + ")";
    return text;
  };
  std::ostringstream md;
  md << "Scene `" << scenePath << "`, database `" << database << "` (" << frames << " frames at "
     << formatNumber(1.0 / dtRec) << " Hz), " << seeds << " seeds per setting, " << formatNumber(duration)
     << " s simulated per run; mean (seed standard deviation). Holdup, mean stay, crossing rate and the stays' KS "
        "distance against the database's reference period; field RMS: time-averaged alpha_P of the tracers against "
        "the frames'; coverage: droplets per particle against the finest setting's pooled runs (its own row: "
        "against its other seeds, the statistical floor); overspray: difference from the finest setting's.\n\n";
  md << "| knob | value | wall s | CPU s | holdup | mean stay | crossing rate | stays KS | field RMS | "
        "coverage KS | coverage mean | p10 | p90 | overspray |\n";
  md << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    md << "| " << r.setting.knob << " | " << r.setting.label << " | " << cell(r.wall, false) << " | "
       << cell(r.cpu, false) << " | " << cell(r.holdup, true) << " | " << cell(r.stay, true) << " | "
       << cell(r.crossing, true) << " | " << cell(r.staysKs, false) << " | " << cell(r.fieldRms, false) << " | "
       << cell(r.coverageKs, false) << " | " << cell(r.coverageMean, true) << " | " << cell(r.p10, true) << " | "
       << cell(r.p90, true) << " | " << cell(r.overspray, false) << " |\n";
  }
  for (const auto& [id, why] : failures) md << "\nNot run: " << id << ": " << why << "\n";
  if (std::isfinite(databaseWall))
    md << "\nThe database job itself: " << formatNumber(databaseWall) << " s of wall time.\n";
  {
    std::ofstream f(out / "accuracy.md");
    f << md.str();
  }
  auto staysError = [](const Row& r) { return r.staysError(); };
  auto coverageError = [](const Row& r) { return r.coverageKs.mean; };
  plotErrorAgainstTime(rows, +staysError, "spray-zone stays against the full simulation (" + sceneName + ")",
                       "log10 largest of |holdup|, |stay|, |crossing| errors and KS", (out / "accuracy-stays.svg").string());
  plotErrorAgainstTime(rows, +coverageError, "coverage against the finest setting (" + sceneName + ")",
                       "log10 KS of droplets per particle", (out / "accuracy-coverage.svg").string());
  json front = json::array();
  for (std::size_t i : paretoFront(rows, +staysError)) front.push_back(rows[i].setting.id);
  const json document = {{"scene", scenePath}, {"database", database}, {"seeds", seeds}, {"duration_s", duration},
                         {"runs", runsJson}, {"pareto_front_stays", front}, {"database_wall_s", databaseWall}};
  {
    std::ofstream f(out / "accuracy.json");
    f << document.dump(1) << "\n";
  }
  std::cout << md.str();
  return {{"document", (out / "accuracy.md").string()}, {"runs", runsJson.size()}, {"pareto_front_stays", front}};
}

const bool registered = addBenchmark(
    "accuracy", "accuracy versus time: a ladder of rCFD settings on one scene and database (docs/accuracy.md)",
    runAccuracy);

}  // namespace
}  // namespace rcfd::bench
