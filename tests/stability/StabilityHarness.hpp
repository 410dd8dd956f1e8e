#pragma once
/// \file StabilityHarness.hpp
/// Whole jobs through the real rcfd-solve binary, and the two ways a job of the stability suite may end
/// (docs/stability.md): exit 0 with every output finite and bounded, or exit 2 with a message that names
/// the offending field by its JSON pointer or dataset path. Anything else -- another exit code, a signal,
/// a sanitizer report, a run past its time bound -- is a failure described in words.

#include <hdf5.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../jobs/SolveChild.hpp"
#include "core/Hdf5.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "fields/FieldDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "scene/SceneLoader.hpp"

namespace rcfd::stability {

namespace fs = std::filesystem;
using nlohmann::json;

/// How a job ended.
struct Outcome {
  int exitCode = -1;       ///< -1: killed after its time bound
  bool timedOut = false;
  double seconds = 0.0;    ///< wall time of the process
  std::string stderrText;  ///< what rcfd-solve printed on stderr
  std::string describe() const {
    std::ostringstream s;
    s << (timedOut ? std::string("no exit within its time bound") : "exit " + std::to_string(exitCode)) << " after "
      << seconds << " s; stderr:\n"
      << stderrText.substr(stderrText.size() > 4000 ? stderrText.size() - 4000 : 0);
    return s.str();
  }
};

/// Writes `job` to dir/job.json and runs `rcfd-solve run dir/job.json --out dir/out --threads T [extra]`,
/// killing it after `timeoutSeconds`.
inline Outcome runJob(const json& job, const fs::path& dir, double timeoutSeconds, int threads = 1,
                      const std::vector<std::string>& extraArguments = {}) {
  fs::create_directories(dir);
  std::ofstream(dir / "job.json") << job.dump(2);
  const auto start = std::chrono::steady_clock::now();
  Outcome o;
  {
    std::vector<std::string> arguments = {"run", (dir / "job.json").string(), "--out", (dir / "out").string(),
                                          "--threads", std::to_string(threads)};
    arguments.insert(arguments.end(), extraArguments.begin(), extraArguments.end());
    rcfd::test::SolveChild child(arguments, dir / "stderr.txt");
    o.exitCode = child.wait(timeoutSeconds);
    o.timedOut = o.exitCode == -1;
  }  // a child still running is killed here
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ifstream err(dir / "stderr.txt");
  o.stderrText.assign(std::istreambuf_iterator<char>(err), {});
  return o;
}

/// Empty when an exit-2 message is a clear input error: rcfd-solve's "error: invalid input:" line, and
/// every violation naming a JSON pointer ("/scene/rcfd/dt") or an HDF5 dataset or attribute
/// ("/frames/alpha_p", "/@dt_rec").
inline std::string inputErrorProblem(const Outcome& o) {
  if (o.exitCode != 2) return "expected exit 2, got " + o.describe();
  const auto at = o.stderrText.find("error: invalid input: ");
  if (at == std::string::npos) return "exit 2 without an \"error: invalid input:\" line: " + o.describe();
  // Every line of the message after the first names a pointer; a one-line message has one after the source.
  static const std::regex pointer(R"((^|[\s:(])/[A-Za-z_@0-9])");
  const std::string message = o.stderrText.substr(at);
  if (!std::regex_search(message, pointer)) return "the input error names no JSON pointer or dataset: " + message;
  return {};
}

/// JSON pointer of key `k` below `base`.
inline std::string below(const std::string& base, const std::string& k) { return base + "/" + k; }

/// Every null in a summary that stands for a number is a NaN or infinity the JSON writer could not
/// print, except the keys documented as null when there is nothing to compute (no reference, no stay,
/// no dominant frequency, no sampling bound of a constant probe signal, a pressure-drop series too
/// short for its statistics: docs/calibration.md, docs/database.md).
inline void findNulls(const json& v, const std::string& at, std::vector<std::string>& out) {
  static const std::set<std::string> nullable = {
      "stay_comparison", "coverage_comparison", "reference_coverage", "dominant_frequency_hz", "penalty_minimum_d0",
      "binding_d0", "selected_d0", "error", "crossings_per_member_per_s", "crossing_rate_relative_error",
      "mean_relative_error", "longest_compared_s", "rtd_ks_distance", "holdup_relative_error",
      "residence_time_mean_relative_error", "bound_s", "largest_admissible_dt_rec_s", "satisfied",
      "mean_pa", "std_pa", "frequency_resolution_hz",
      "periods", "holdup_relative_difference", "against_sampled_period"};  // (no reference period, or none in it)  // (a pressure-drop series of fewer than 4 samples)
  if (v.is_null()) {
    const std::string key = at.substr(at.rfind('/') + 1);
    if (!nullable.count(key)) out.push_back("summary.json" + at + " is null (a NaN or infinity?)");
  } else if (v.is_object()) {
    for (auto it = v.begin(); it != v.end(); ++it) findNulls(it.value(), below(at, it.key()), out);
  } else if (v.is_array()) {
    for (std::size_t i = 0; i < v.size(); ++i) findNulls(v[i], below(at, std::to_string(i)), out);
  } else if (v.is_number_float() && !std::isfinite(v.get<double>())) {
    out.push_back("summary.json" + at + " is not finite");
  }
}

/// Names of every floating-point dataset in an HDF5 file.
inline std::vector<std::string> floatDatasets(const std::string& path) {
  std::vector<std::string> names;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) return names;
  auto visit = [](hid_t root, const char* name, const H5O_info_t* info, void* data) -> herr_t {
    if (info->type != H5O_TYPE_DATASET) return 0;
    const hid_t set = H5Dopen2(root, name, H5P_DEFAULT);
    const hid_t type = H5Dget_type(set);
    if (H5Tget_class(type) == H5T_FLOAT) static_cast<std::vector<std::string>*>(data)->push_back("/" + std::string(name));
    H5Tclose(type);
    H5Dclose(set);
    return 0;
  };
  H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_NATIVE, visit, &names, H5O_INFO_BASIC);
  H5Fclose(file);
  return names;
}

/// Every value of every floating-point dataset is finite, except those documented as NaN where not
/// computed (`nanAllowed`, by prefix).
inline void checkFiniteDatasets(const fs::path& file, const std::vector<std::string>& nanAllowed,
                                std::vector<std::string>& out) {
  if (!fs::exists(file)) {
    out.push_back(file.filename().string() + " is missing");
    return;
  }
  h5::File f(file.string(), h5::File::Mode::ReadOnly);
  for (const auto& name : floatDatasets(file.string())) {
    if (std::any_of(nanAllowed.begin(), nanAllowed.end(), [&](const std::string& p) { return name.rfind(p, 0) == 0; }))
      continue;
    const auto values = f.readDoubles(name);
    const auto bad = std::find_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); });
    if (bad != values.end()) {
      out.push_back(file.filename().string() + ":" + name + "[" + std::to_string(bad - values.begin()) + "] is " +
                    std::to_string(*bad));
    }
  }
}

inline void checkRange(const std::vector<double>& values, double lo, double hi, const std::string& what,
                       std::vector<std::string>& out) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!(values[i] >= lo && values[i] <= hi)) {
      out.push_back(what + "[" + std::to_string(i) + "] = " + std::to_string(values[i]) + " is outside [" +
                    std::to_string(lo) + ", " + std::to_string(hi) + "]");
      return;
    }
  }
}

/// One tracer run's summary `s` and its result tree in `r` below `at` ("" for the file's root, an
/// ensemble member's group otherwise): tracers all there and inside the apparatus, coverage in [0, 1],
/// the spray's books closed, counts >= 0.
inline void checkTracerResults(const json& s, const h5::File& r, const std::string& at, const Scene& scene,
                               std::vector<std::string>& out) {
  const std::string where = at.empty() ? std::string() : at + ": ";
  const auto x = r.readDoubles(at + "/tracers/x"), y = r.readDoubles(at + "/tracers/y"),
             z = r.readDoubles(at + "/tracers/z");
  if (std::int64_t(x.size()) != scene.rcfd.tracers || y.size() != x.size() || z.size() != x.size()) {
    out.push_back("result.h5" + at + " holds " + std::to_string(x.size()) + " tracers, the scene " +
                  std::to_string(scene.rcfd.tracers));
    return;
  }
  if (s.value("tracers", std::int64_t(-1)) != scene.rcfd.tracers) out.push_back(where + "summary.json/tracers is not the scene's count");
  const Apparatus apparatus(scene.apparatus);
  // The kernel keeps tracers inside up to the wall test's tolerance band (docs/physics.md).
  const double tolerance = 4.0 * apparatus.boundaryTolerance();
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double d = apparatus.signedDistance({x[i], y[i], z[i]});
    if (!(d >= -tolerance)) {
      out.push_back(where + "tracer " + std::to_string(i) + " at (" + std::to_string(x[i]) + ", " + std::to_string(y[i]) + ", " +
                    std::to_string(z[i]) + ") is outside the apparatus (signed distance " + std::to_string(d) + " m)");
      break;
    }
  }
  if (r.exists(at + "/coverage/per_tracer")) {
    checkRange(r.readDoubles(at + "/coverage/per_tracer"), 0.0, 1.0, at + "/coverage/per_tracer", out);
    checkRange(r.readDoubles(at + "/coverage/droplets_per_particle"), 0.0, INFINITY,
               at + "/coverage/droplets_per_particle", out);
    for (const char* k : {"mean", "median", "p10", "p90"}) {
      const double v = s["coverage"][k].get<double>();
      if (!(v >= 0.0 && v <= 1.0)) out.push_back(where + "summary.json/coverage/" + k + " is outside [0, 1]");
    }
  }
  if (s.contains("mass_balance")) {
    const json& m = s["mass_balance"];
    const double injected = m["injected_kg"].get<double>();
    for (const char* k : {"injected_kg", "deposited_kg", "airborne_kg", "overspray_kg", "residual_kg", "on_tracers_kg",
                          "pending_in_cells_kg"}) {
      if (!(m[k].get<double>() >= 0.0)) out.push_back(where + "summary.json/mass_balance/" + k + " is negative");
    }
    const double closure = m["closure_error_kg"].get<double>();
    if (!(std::abs(closure) <= 1e-9 * injected + 1e-300)) {
      out.push_back(where + "the spray's mass balance does not close: closure error " + std::to_string(closure) + " kg of " +
                    std::to_string(injected) + " kg injected");
    }
    // What the tracers hold plus what waits in cells is what was deposited.
    const double held = m["on_tracers_kg"].get<double>() + m["pending_in_cells_kg"].get<double>();
    if (!(std::abs(held - m["deposited_kg"].get<double>()) <= 1e-9 * injected + 1e-300)) {
      out.push_back(where + "deposited mass " + std::to_string(m["deposited_kg"].get<double>()) +
                    " kg is not what the tracers and cells hold, " + std::to_string(held) + " kg");
    }
    const double f = s["overspray_fraction"].get<double>();
    if (!(f >= 0.0 && f <= 1.0 + 1e-12)) out.push_back(where + "summary.json/overspray_fraction is outside [0, 1]");
  }
  if (r.exists(at + "/holdup/particles")) {
    checkRange(r.readDoubles(at + "/holdup/particles"), 0.0, INFINITY, at + "/holdup/particles", out);
  }
}

/// The outputs of a finished tracer run (a spray job, or one D0 run of a calibration), checked by
/// checkTracerResults; an ensemble's members each the same way, the K members of the job with K
/// distinct seeds (docs/formats.md, "Ensembles").
inline void checkTracerRun(const fs::path& dir, const Scene& scene, std::vector<std::string>& out,
                           int ensembleMembers = 1) {
  const json s = json::parse(std::ifstream(dir / "summary.json"));
  findNulls(s, "", out);
  checkFiniteDatasets(dir / "result.h5", {}, out);
  if (!out.empty()) return;
  const h5::File r((dir / "result.h5").string(), h5::File::Mode::ReadOnly);
  checkTracerResults(s, r, "", scene, out);
  if (ensembleMembers == 1) {
    if (s.contains("ensemble") || r.exists("/ensemble")) out.push_back("a run of one member writes an ensemble block");
    return;
  }
  if (!s.contains("ensemble") || !r.exists("/ensemble/members")) {
    out.push_back("an ensemble of " + std::to_string(ensembleMembers) + " writes no ensemble block");
    return;
  }
  const auto members = r.children("/ensemble/members");
  const auto seeds = r.readInt64s("/ensemble/seeds");
  if (int(members.size()) != ensembleMembers || r.intAttribute("/ensemble", "members") != ensembleMembers ||
      s["ensemble"]["members"].get<int>() != ensembleMembers || int(seeds.size()) != ensembleMembers) {
    out.push_back("an ensemble of " + std::to_string(ensembleMembers) + " holds " + std::to_string(members.size()) +
                  " members and " + std::to_string(seeds.size()) + " seeds");
    return;
  }
  if (std::set<std::int64_t>(seeds.begin(), seeds.end()).size() != seeds.size()) out.push_back("two members share a seed");
  for (const auto& m : members) {
    const std::string at = "/ensemble/members/" + m;
    const json ms = json::parse(r.readString(at + "/summary"));
    std::vector<std::string> member;
    findNulls(ms, "", member);
    if (member.empty()) checkTracerResults(ms, r, at, scene, member);
    for (auto& p : member) out.push_back("member " + m + ": " + p);
  }
}

/// The outputs of a finished database job: database.h5 passes the reader's validation, every frame's
/// alpha_P is in [0, 1] and holds the bed's parcel volume, the reference series are finite.
inline void checkDatabaseJob(const fs::path& dir, const Scene& scene, std::vector<std::string>& out) {
  const json s = json::parse(std::ifstream(dir / "summary.json"));
  findNulls(s, "", out);
  checkFiniteDatasets(dir / "result.h5", {}, out);
  checkFiniteDatasets(dir / "database.h5", {}, out);
  if (!out.empty()) return;
  std::shared_ptr<FieldDatabase> db;
  try {
    db = FieldDatabase::open((dir / "database.h5").string());
  } catch (const std::exception& e) {
    out.push_back(std::string("database.h5 does not load: ") + e.what());
    return;
  }
  if (db->frameCount() != s["frames"].get<int>()) out.push_back("database.h5 holds another frame count than the summary");
  const double d = scene.particles.diameter * scene.dem.coarse_graining;
  const double parcelVolume = std::numbers::pi / 6.0 * d * d * d;
  const double bed = double(s["particles"].get<std::int64_t>()) * parcelVolume;
  const double cellVolume = db->grid().cellVolume();
  for (int n = 0; n < db->frameCount(); ++n) {
    const auto f = db->frame(n);
    double volume = 0.0;
    for (std::size_t c = 0; c < f->alpha_p.size(); ++c) {
      const float a = f->alpha_p[c];
      if (!(a >= 0.0f && a <= 1.0f)) {
        out.push_back("frame " + std::to_string(n) + " cell " + std::to_string(c) + ": alpha_P = " + std::to_string(a));
        return;
      }
      volume += double(a) * cellVolume * db->fluidFraction()[c];
    }
    // The mapping and the over-packing treatment move parcel volume, never lose it (to float rounding).
    if (!(std::abs(volume - bed) <= 1e-4 * bed + 1e-18)) {
      out.push_back("frame " + std::to_string(n) + " holds a particle volume of " + std::to_string(volume) +
                    " m3, the bed's parcels " + std::to_string(bed) + " m3");
      return;
    }
  }
}

/// The outputs of a finished calibration: the summary, result.h5 (whose per-D0 scores are NaN where not
/// computed, docs/calibration.md) and every D0 run's own outputs.
inline void checkCalibrationJob(const fs::path& dir, const Scene& scene, std::vector<std::string>& out) {
  const json s = json::parse(std::ifstream(dir / "summary.json"));
  findNulls(s["selection"], "/selection", out);
  checkFiniteDatasets(dir / "result.h5", {"/calibration/"}, out);
  for (const auto& run : s["d0"]) {
    const double v = run["value"].get<double>();
    if (!(v >= 0.0 && std::isfinite(v))) out.push_back("a D0 of the summary is not finite and >= 0");
  }
  for (const auto& entry : fs::directory_iterator(dir / "runs")) {
    if (!fs::exists(entry.path() / "summary.json")) {
      out.push_back(entry.path().filename().string() + " has no summary.json");
      continue;
    }
    std::vector<std::string> run;
    checkTracerRun(entry.path(), scene, run);
    for (auto& p : run) out.push_back(entry.path().filename().string() + ": " + p);
  }
}

/// Empty when an exit 3 is the documented ending of a gas solve that does not converge (docs/stability.md):
/// the message names the time, the DEM step, the residual reached and /gas/pressure_tolerance, and the
/// checkpoint it names is there.
inline std::string gasNonConvergenceProblem(const Outcome& o, const fs::path& dir) {
  if (o.exitCode != 3) return "expected exit 3, got " + o.describe();
  for (const char* part : {"error: run failed: CFD-DEM at t = ", "DEM step", "the pressure solver did not converge",
                           "relative residual", "/gas/pressure_tolerance", "the checkpoint of t = "}) {
    if (o.stderrText.find(part) == std::string::npos) return std::string("no \"") + part + "\" in " + o.describe();
  }
  if (!fs::exists(dir / "out" / "checkpoint.h5")) return "the checkpoint the message names is missing";
  return {};
}

/// What is wrong with a job's ending (empty: nothing). `scene` is the job's scene as the solver loads it.
inline std::string outcomeProblem(const Outcome& o, const json& job, const fs::path& dir) {
  if (o.exitCode == 2) return inputErrorProblem(o);
  if (o.exitCode != 0) return "neither exit 0 nor exit 2: " + o.describe();
  std::vector<std::string> problems;
  try {
    const JobSpec spec = loadJob(job, "job", dir.string());
    const fs::path out = dir / "out";
    if (spec.kind == "spray") checkTracerRun(out, spec.scene, problems, spec.ensemble_members);
    if (spec.kind == "database") checkDatabaseJob(out, spec.scene, problems);
    if (spec.kind == "calibration") checkCalibrationJob(out, spec.scene, problems);
  } catch (const std::exception& e) {
    problems.push_back(std::string("reading the outputs: ") + e.what());
  }
  std::string text;
  for (const auto& p : problems) text += p + "\n";
  return text;
}

/// A scene's grid and open fractions, for analytic databases.
struct SceneGrid {
  CartesianGrid grid;
  std::vector<float> fluid;
};
inline SceneGrid sceneGrid(const json& sceneDocument) {
  const Scene s = loadScene(sceneDocument);
  const Apparatus a(s.apparatus);
  SceneGrid g{makeGrid(a, s.grid), {}};
  const auto open = openFractions(a, g.grid);
  g.fluid.assign(open.begin(), open.end());
  return g;
}

}  // namespace rcfd::stability
