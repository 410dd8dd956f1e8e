#include "jobs/Ensemble.hpp"

#include <algorithm>
#include <cstdio>
#include <set>

#include "analysis/EnsembleStatistics.hpp"
#include "core/AxisTicks.hpp"
#include "core/Errors.hpp"
#include "core/Svg.hpp"

namespace rcfd {
namespace {

using nlohmann::json;

std::uint64_t splitMix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

constexpr double kLevel = 0.95;

/// The numbers at `pointer` in every member's summary, or nothing when one of them has none there.
bool valuesAt(const std::vector<json>& members, const json::json_pointer& pointer, std::vector<double>& values) {
  values.clear();
  for (const auto& m : members) {
    if (!m.contains(pointer)) return false;
    const json& v = m.at(pointer);
    if (!v.is_number()) return false;
    values.push_back(v.get<double>());
  }
  return true;
}

/// The coverage histogram's counts of every member ([K][bins]) when all have the same edges.
bool memberHistograms(const std::vector<json>& members, std::vector<double>& edges,
                      std::vector<std::vector<double>>& counts) {
  const json::json_pointer e("/coverage/histogram/edges"), c("/coverage/histogram/counts");
  counts.clear();
  for (const auto& m : members) {
    if (!m.contains(e) || !m.contains(c)) return false;
    const auto memberEdges = m.at(e).get<std::vector<double>>();
    if (counts.empty()) edges = memberEdges;
    if (memberEdges != edges) return false;
    counts.push_back(m.at(c).get<std::vector<double>>());
    if (counts.back().size() + 1 != edges.size()) return false;
  }
  return !counts.empty();
}

}  // namespace

std::string ensembleMemberName(std::size_t k) {
  const std::string digits = std::to_string(k);
  return digits.size() < 2 ? "0" + digits : digits;
}

std::vector<std::uint64_t> ensembleSeeds(std::uint64_t jobSeed, int members) {
  constexpr std::uint64_t kMask = (std::uint64_t(1) << 53) - 1;
  std::vector<std::uint64_t> seeds;
  std::set<std::uint64_t> taken;
  for (int k = 0; k < members; ++k) {
    std::uint64_t s = jobSeed;
    if (k > 0) {
      s = splitMix64(splitMix64(jobSeed) ^ std::uint64_t(k)) & kMask;
      while (taken.count(s)) s = splitMix64(s) & kMask;  // a collision (odds 2^-53 per pair): mix again
    }
    seeds.push_back(s);
    taken.insert(s);
  }
  return seeds;
}

const std::vector<std::string>& ensembleStatisticPointers() {
  static const std::vector<std::string> pointers = {
      "/coverage/mean",
      "/coverage/median",
      "/coverage/p10",
      "/coverage/p90",
      "/droplets_per_tracer_mean",
      "/overspray_fraction",
      "/mass_balance/injected_kg",
      "/mass_balance/deposited_kg",
      "/mass_balance/airborne_kg",
      "/mass_balance/overspray_kg",
      "/holdup/mean",
      "/holdup/mean_fraction",
      "/residence_time/mean_s",
      "/residence_time/median_s",
      "/residence_time/p90_s",
      "/residence_time/stays",
      "/residence_time/crossings_per_tracer_per_s",
      "/coverage_comparison/ks_distance",
      "/coverage_comparison/mean_relative_error",
      "/coverage_comparison/p10_relative_error",
      "/coverage_comparison/p90_relative_error",
      "/coverage_comparison/droplets_per_particle_relative_error",
      "/stay_comparison/ks_distance",
      "/stay_comparison/mean_relative_error",
      "/stay_comparison/crossing_rate_relative_error",
      "/probes/penalty_mean",
      "/probes/rms_mean",
      "/path/jumps",
      "/path/mean_jump_similarity",
      "/path/mean_sequence_frames",
  };
  return pointers;
}

json ensembleSummary(const std::vector<json>& members, const std::vector<std::uint64_t>& seeds) {
  const int k = int(members.size());
  json block = {{"members", k},
                {"seeds", seeds},
                {"other_keys", "member 0's: the run of the job's seed, as the job without ensemble writes it"},
                {"interval",
                 {{"level", kLevel},
                  {"of", "the mean over the members"},
                  {"degrees_of_freedom", k - 1},
                  {"t", k > 1 ? analysis::studentTQuantile(0.5 + 0.5 * kLevel, k - 1) : 0.0}}}};
  std::vector<double> values;
  for (const auto& p : ensembleStatisticPointers()) {
    const json::json_pointer pointer(p);
    if (valuesAt(members, pointer, values)) block[pointer] = analysis::toJson(analysis::spreadOf(values, kLevel), values);
  }
  std::vector<double> edges;
  std::vector<std::vector<double>> counts;
  if (memberHistograms(members, edges, counts)) {
    const std::size_t bins = edges.size() - 1;
    std::vector<double> mean(bins), sd(bins), sem(bins), lo(bins), hi(bins), mn(bins), mx(bins), binValues;
    for (std::size_t b = 0; b < bins; ++b) {
      binValues.clear();
      for (const auto& c : counts) binValues.push_back(c[b]);
      const auto s = analysis::spreadOf(binValues, kLevel);
      mean[b] = s.mean, sd[b] = s.sd, sem[b] = s.sem, lo[b] = s.ciLow, hi[b] = s.ciHigh, mn[b] = s.min, mx[b] = s.max;
    }
    block["coverage"]["histogram"] = {{"edges", edges},      {"unit", "tracers per bin"},
                                      {"mean", mean},        {"sd", sd},
                                      {"sem", sem},          {"ci95_low", lo},
                                      {"ci95_high", hi},     {"min", mn},
                                      {"max", mx},           {"member_counts", counts}};
  }
  return block;
}

void writeEnsembleResults(h5::File& out, const json& ensemble, const std::vector<std::string>& memberFiles,
                          const std::vector<json>& memberSummaries) {
  const std::size_t k = memberFiles.size();
  out.createGroup("/ensemble");
  out.setAttribute("/ensemble", "members", std::int64_t(k));
  out.setAttribute("/ensemble", "level", kLevel);
  out.setAttribute("/ensemble", "t", ensemble["interval"]["t"].get<double>());
  const auto seeds = ensemble["seeds"].get<std::vector<std::uint64_t>>();
  out.write("/ensemble/seeds", std::vector<std::int64_t>(seeds.begin(), seeds.end()));
  // Every statistic's member values, at its summary pointer.
  std::vector<double> values;
  for (const auto& p : ensembleStatisticPointers()) {
    if (valuesAt(memberSummaries, json::json_pointer(p), values)) out.write("/ensemble/values" + p, values);
  }
  if (ensemble.contains(json::json_pointer("/coverage/histogram"))) {
    const json& h = ensemble["coverage"]["histogram"];
    const std::string g = "/ensemble/coverage/histogram_";
    out.write(g + "edges", h["edges"].get<std::vector<double>>());
    std::vector<std::int64_t> counts;
    const auto members = h["member_counts"].get<std::vector<std::vector<double>>>();
    for (const auto& row : members) {
      for (const double c : row) counts.push_back(std::int64_t(c));
    }
    out.write(g + "counts", counts, {hsize_t(members.size()), hsize_t(members.front().size())});
    for (const char* name : {"mean", "sd", "sem", "ci95_low", "ci95_high", "min", "max"}) {
      out.write(g + name, h[name].get<std::vector<double>>());
    }
  }
  // The members' own results: member 0's are the root's (linked, not copied).
  for (std::size_t m = 0; m < k; ++m) {
    const std::string group = "/ensemble/members/" + ensembleMemberName(m);
    out.createGroup(group);
    out.setAttribute(group, "seed", std::int64_t(seeds.at(m)));
    out.writeString(group + "/summary", memberSummaries.at(m).dump(2));
    if (m == 0) {
      for (const auto& name : out.children("/")) {
        if (name != "scene" && name != "ensemble") out.hardLink("/" + name, group + "/" + name);
      }
      continue;
    }
    const h5::File member(memberFiles[m], h5::File::Mode::ReadOnly);
    for (const auto& name : member.children("/")) {
      if (name != "scene") out.copyFrom(member, "/" + name, group + "/" + name);
    }
  }
}

std::string writeEnsembleCoverageFigure(const json& ensemble, double simTime, const std::string& outDir) {
  const json& h = ensemble.at("coverage").at("histogram");
  const auto edges = h["edges"].get<std::vector<double>>();
  const auto mean = h["mean"].get<std::vector<double>>();
  const auto lo = h["ci95_low"].get<std::vector<double>>();
  const auto hi = h["ci95_high"].get<std::vector<double>>();
  const auto mn = h["min"].get<std::vector<double>>();
  const auto mx = h["max"].get<std::vector<double>>();
  double total = 0.0;
  for (const double c : mean) total += c;
  total = std::max(total, 1.0);
  double peak = 1.0;
  for (std::size_t b = 0; b < mean.size(); ++b) peak = std::max({peak, mean[b], hi[b], mx[b]});
  const double top = peak / total * 1.1;
  SvgDocument svg(0.0, 1.0, 0.0, top, 640, 420, 55);
  for (std::size_t b = 0; b < mean.size(); ++b) {
    const double x0 = edges[b], x1 = edges[b + 1], xc = 0.5 * (x0 + x1), w = 0.25 * (x1 - x0);
    svg.rect(x0, 0.0, x1, mean[b] / total, "#3b518b", "#fff", 0.5);
    // The 95 % interval of the mean (the band) and the members' range (whiskers).
    svg.rect(x0 + 0.1 * (x1 - x0), std::max(0.0, lo[b]) / total, x1 - 0.1 * (x1 - x0), hi[b] / total, "#f0a030",
             "none", 0.0, 0.55);
    svg.line(xc, mn[b] / total, xc, mx[b] / total, "#222", 1.0);
    svg.line(xc - w, mn[b] / total, xc + w, mn[b] / total, "#222", 1.0);
    svg.line(xc - w, mx[b] / total, xc + w, mx[b] / total, "#222", 1.0);
  }
  const json& median = ensemble.at("coverage").at("median");
  const double m = median["mean"].get<double>();
  const double mLo = median["ci95"][0].get<double>(), mHi = median["ci95"][1].get<double>();
  svg.rect(std::max(0.0, mLo), 0.0, std::min(1.0, mHi), top, "#c00", "none", 0.0, 0.12);
  svg.line(m, 0.0, m, top, "#c00", 1.5, "5,3");
  svg.axes("surface coverage phi [-] (Eq. 15)", "fraction of particles [-]");
  const int members = ensemble["members"].get<int>();
  char title[200];
  std::snprintf(title, sizeof title, "Coverage distribution after %s, %d members: median %.3f [%.3f, %.3f]",
                durationLabel(simTime).c_str(), members, m, mLo, mHi);
  svg.textPx(320, 20, title, 14, "middle");
  svg.textPx(320, 38, "bars: mean over members; orange: 95 % interval of the mean; whiskers: members' range", 11,
             "middle");
  svg.save(outDir + "/coverage.svg");
  return "coverage.svg";
}

}  // namespace rcfd
