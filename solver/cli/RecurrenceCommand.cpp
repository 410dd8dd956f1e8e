// rcfd-solve recurrence DB.h5 [--svg OUT.svg] [--norm l2|l1|max] [--field F]: the recurrence matrix of
// Eq. (6)-(7) with its summary, the sampling criterion of Eq. (8), the matrix stored into the database
// (/recurrence/matrix) and the recurrence plot (the paper's Fig. 6).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "fields/FieldDatabase.hpp"
#include "recurrence/RecurrenceMatrix.hpp"
#include "recurrence/RecurrencePlot.hpp"
#include "recurrence/SamplingCriterion.hpp"

namespace rcfd::cli {
namespace {

struct Options {
  std::string database;
  std::string svg;
  std::string norm = "l2";
  std::string field = "alpha_p";
  std::string samplingField = "u_p.y";
  std::vector<std::string> probes;
  bool allCells = false;
  bool noStore = false;
  bool json = false;
  std::string gram = "auto";
  std::int64_t cacheBytes = 0;
  double memoryBudgetMb = 1536.0;
};

std::string fmt(double v, const char* spec = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}

SamplingProbe parseProbe(const std::string& text, std::size_t index) {
  SamplingProbe p;
  std::string s = text;
  for (char& c : s)
    if (c == ',') c = ' ';
  std::istringstream in(s);
  double x, y, z;
  std::string rest;
  if (!(in >> x >> y >> z) || (in >> rest)) {
    throw InputError("rcfd-solve recurrence", "--probe",
                     "\"" + text + "\" is not a point; give x,y,z in metres, e.g. 0,0.075,0.05");
  }
  p.name = "probe " + std::to_string(index + 1);
  p.position = Eigen::Vector3d(x, y, z);
  return p;
}

int run(const Options& o) {
  RecurrenceOptions ro;
  ro.norm = parseRecurrenceNorm(o.norm);
  ro.field = o.field;
  if (o.gram == "double") ro.gram = GramPrecision::Double;
  else if (o.gram == "float") ro.gram = GramPrecision::FloatChunked;
  else if (o.gram != "auto")
    throw InputError("rcfd-solve recurrence", "--gram", "\"" + o.gram + "\" is not one of: auto double float");
  parseFieldComponent(o.field);               // refuse a bad name before loading anything
  parseFieldComponent(o.samplingField, "--sampling-field");
  if (!(o.memoryBudgetMb > 0.0)) throw InputError("rcfd-solve recurrence", "--memory-budget", "must be > 0 [MB]");
  ro.memoryBudgetBytes = std::int64_t(o.memoryBudgetMb * 1024.0 * 1024.0);
  std::vector<SamplingProbe> probes;
  for (std::size_t i = 0; i < o.probes.size(); ++i) probes.push_back(parseProbe(o.probes[i], i));

  const auto openStart = std::chrono::steady_clock::now();
  auto db = FieldDatabase::open(o.database, FrameStorage{o.cacheBytes});
  const double openSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - openStart).count();
  const auto& g = db->grid();
  std::int64_t open = 0;
  for (float f : db->fluidFraction()) open += f > 0.0f ? 1 : 0;
  std::cout << "database: " << o.database << "\n  frames N = " << db->frameCount()
            << ", dt_rec = " << fmt(db->dtRec()) << " s (" << fmt(db->frameCount() * db->dtRec())
            << " s sampled), grid " << g.shape[0] << " x " << g.shape[1] << " x " << g.shape[2] << ", "
            << open << " open cells\n  opened in " << fmt(openSeconds, "%.3f") << " s ("
            << (o.cacheBytes == 0 ? "all frames in RAM" : "frame cache of " + std::to_string(o.cacheBytes) + " bytes")
            << ")\n";

  const RecurrenceMatrix m = computeRecurrenceMatrix(*db, ro);
  const RecurrenceSummary summary = summariseRecurrence(m.R);
  std::cout << "recurrence matrix (Eq. 6-7; norm " << toString(m.norm) << ", field " << m.field << "):\n"
            << "  computed in " << fmt(m.seconds, "%.3f") << " s (" << m.frameBlocks << " frame block"
            << (m.frameBlocks == 1 ? "" : "s") << "), normalisation max D = " << fmt(m.normalisation) << "\n"
            << "  mean off-diagonal R = " << fmt(summary.meanOffDiagonal) << "\n";
  if (m.norm == RecurrenceNorm::L2) {
    std::cout << "  Gram arithmetic: " << (m.gramUsed == GramPrecision::Double ? "double" : "float chunks summed in double");
    if (ro.gram == GramPrecision::Auto)
      std::cout << " (spot check max |R - R_exact| = " << fmt(m.spotCheckError, "%.2g")
                << (m.autoFellBack ? ", above the tolerance: recomputed in double" : "") << ")";
    std::cout << "\n";
  }
  if (m.clampedNegatives > 0)
    std::cout << "  " << m.clampedNegatives << " round-off negative distances set to 0\n";
  std::cout << "  strongest recurrence lags:";
  if (summary.strongestLags.empty()) std::cout << " none (no local maximum of the diagonal means)";
  for (const auto& lag : summary.strongestLags) {
    std::cout << "\n    lag " << lag.lag << " frames (" << fmt(lag.lag * db->dtRec()) << " s): mean R "
              << fmt(lag.meanR);
  }
  std::cout << "\n";

  if (probes.empty() && !o.allCells) probes = probesFromSceneJson(db->sceneJson());
  const SamplingReport s = samplingCriterion(*db, o.samplingField, o.allCells ? std::vector<SamplingProbe>{} : probes);
  std::cout << "sampling criterion (Eq. 8, field " << s.field << ", "
            << (s.allCells ? "all " + std::to_string(s.pointsConsidered) + " open cells" : std::to_string(s.points.size()) + " probes")
            << "):\n";
  for (const auto& p : s.points) {
    std::cout << "  " << p.name << " cell (" << p.cell[0] << ", " << p.cell[1] << ", " << p.cell[2]
              << "): sqrt<g^2> = " << fmt(p.rms) << ", sqrt<g'^2> = " << fmt(p.rateRms) << " /s, bound "
              << fmt(p.bound) << " s\n";
  }
  if (s.allCells) {
    std::cout << "  median bound " << fmt(s.medianBound) << " s; " << s.pointsWithoutVariation
              << " cells without variation skipped\n";
  }
  std::cout << "  largest admissible dt_rec = " << fmt(s.largestAdmissibleDtRec) << " s (at "
            << s.strictest.name << "); database dt_rec = " << fmt(s.dtRec) << " s: "
            << (s.satisfied ? "satisfied" : "NOT satisfied") << "\n";

  const double dtRec = db->dtRec();
  const int frames = db->frameCount();
  db.reset();  // the file must be closed before it is reopened for writing
  if (!o.noStore) {
    try {
      storeRecurrenceMatrix(o.database, m);
    } catch (const RunError& e) {
      throw RunError(std::string(e.what()) + " (the report above is complete; --no-store skips storing)");
    }
    std::cout << "matrix stored in " << o.database << ":/recurrence/matrix\n";
  }
  if (!o.svg.empty()) {
    recurrencePlot(m.R, dtRec,
                   "Recurrence plot (" + m.field + ", " + toString(m.norm) + ", " + std::to_string(frames) +
                       " frames)")
        .save(o.svg);
    std::cout << "recurrence plot: " << o.svg << "\n";
  }
  if (o.json) {
    nlohmann::json j;
    j["frames"] = frames;
    j["dt_rec"] = dtRec;
    j["norm"] = toString(m.norm);
    j["field"] = m.field;
    j["matrix_seconds"] = m.seconds;
    j["gram"] = m.gramUsed == GramPrecision::Double ? "double" : "float_chunked";
    j["mean_off_diagonal"] = summary.meanOffDiagonal;
    j["lags"] = nlohmann::json::array();
    for (const auto& lag : summary.strongestLags) j["lags"].push_back({{"lag", lag.lag}, {"mean_r", lag.meanR}});
    j["sampling"] = {{"field", s.field},
                     {"largest_admissible_dt_rec", std::isfinite(s.largestAdmissibleDtRec) ? nlohmann::json(s.largestAdmissibleDtRec) : nlohmann::json(nullptr)},
                     {"satisfied", s.satisfied}};
    std::cout << j.dump() << "\n";
  }
  return exit_code::success;
}

const bool registered = addCommand(
    "recurrence", "recurrence matrix (Eq. 6-7), sampling criterion (Eq. 8), recurrence plot", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("DB", o->database, "field database (HDF5)")->required();
      app.add_option("--svg", o->svg, "write the recurrence plot (like the paper's Fig. 6)");
      std::string norms;
      for (const auto& n : kRecurrenceNorms) norms += std::string("\n  ") + n.name + ": " + n.doc;
      app.add_option("--norm", o->norm, "distance between frames (default l2):" + norms);
      app.add_option("--field", o->field, "alpha_p (default), u_p.x|y|z or u_g.x|y|z");
      app.add_option("--sampling-field", o->samplingField, "field of the sampling criterion (default u_p.y)");
      app.add_option("--probe", o->probes, "probe point x,y,z [m] for the sampling criterion (repeatable; "
                                           "default: the scene's probes, else all open cells)");
      app.add_flag("--all-cells", o->allCells, "sampling criterion over every open cell");
      app.add_option("--cache-bytes", o->cacheBytes, "frame cache size in bytes (default 0: all frames in RAM)");
      app.add_option("--memory-budget", o->memoryBudgetMb, "MB of frames converted to double at a time (default 1536)");
      app.add_option("--gram", o->gram,
                     "L2 arithmetic: auto (default: float GEMM over 512-cell chunks summed in double, spot-checked, "
                     "double if the check fails), double, float");
      app.add_flag("--no-store", o->noStore, "do not write /recurrence/matrix into the database");
      app.add_flag("--json", o->json, "print a JSON summary as the last line");
      return [o] { return run(*o); };
    });

}  // namespace
}  // namespace rcfd::cli
