#include "analysis/CalibrationReport.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <spdlog/spdlog.h>

#include "analysis/CalibrationFigures.hpp"
#include "analysis/KsDistance.hpp"
#include "geometry/Apparatus.hpp"
#include "analysis/StayComparison.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "geometry/SprayZone.hpp"

namespace rcfd::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// What one finished run contributes beyond its scores.
struct RunData {
  std::vector<double> probeTime, probeTracer, probeRecurrence;  ///< the figure's probe only
  std::vector<double> probeTracerAll, probeRecurrenceAll;       ///< [rows][probes]
  std::vector<double> holdup;
  double holdupDt = 0.0, holdupT0 = 0.0;
  std::vector<std::int64_t> durationCounts;  ///< stays per duration in steps
  std::vector<float> midplane, recurrenceMidplane;
};

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw RunError("cannot read " + path);
  return nlohmann::json::parse(in);
}

/// The probe of Fig. 7: the one nearest the spray zone's centre (the paper's spout probe at the
/// height of the spray zone).
std::size_t figureProbe(const Scene& scene) {
  const auto& z = scene.spray.spray_zone;
  const Vec3 centre(z.apex.x(), 0.5 * (z.y_min + z.y_max), z.apex.z());
  std::size_t best = 0;
  for (std::size_t p = 1; p < scene.probes.size(); ++p) {
    if ((scene.probes[p].position - centre).norm() < (scene.probes[best].position - centre).norm()) best = p;
  }
  return best;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + std::ptrdiff_t((v.size() - 1) / 2);  // lower median, as the histogram's
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::vector<float> slice(const std::vector<float>& field, const CartesianGrid& grid, int k) {
  const std::size_t layer = std::size_t(grid.shape[0]) * std::size_t(grid.shape[1]);
  return {field.begin() + std::ptrdiff_t(layer * std::size_t(k)), field.begin() + std::ptrdiff_t(layer * std::size_t(k + 1))};
}

nlohmann::json optionalNumber(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(); }


/// Particles the recurrence field holds in the spray zone: sum over cells of alpha_P x open volume x the
/// share of the cell inside the zone (4 x 4 x 4 points per cell), over the volume of one particle.
double fieldHoldup(const Scene& scene, const CartesianGrid& grid, const std::vector<float>& alpha,
                   const std::vector<float>& fluid) {
  const SprayZone zone(scene.spray.spray_zone, Apparatus(scene.apparatus));
  const auto& p = scene.particles;
  const double particleVolume = 3.14159265358979323846 / 6.0 * p.diameter * p.diameter * p.diameter;
  constexpr int kPoints = 4;
  double volume = 0.0;
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    if (!(alpha[std::size_t(c)] > 0.0f)) continue;
    const auto ijk = grid.cellIjk(c);
    int inside = 0;
    for (int a = 0; a < kPoints; ++a)
      for (int b = 0; b < kPoints; ++b)
        for (int d = 0; d < kPoints; ++d) {
          const Eigen::Vector3d q = grid.origin + grid.spacing.cwiseProduct(Eigen::Vector3d(
                                                      ijk[0] + (a + 0.5) / kPoints, ijk[1] + (b + 0.5) / kPoints,
                                                      ijk[2] + (d + 0.5) / kPoints));
          inside += zone.contains(q);
        }
    const double share = double(inside) / (kPoints * kPoints * kPoints);
    volume += double(alpha[std::size_t(c)]) * grid.cellVolume() * double(fluid[std::size_t(c)]) * share;
  }
  return volume / particleVolume;
}

}  // namespace

int midplaneLayer(const Scene& scene, const CartesianGrid& grid) {
  const double depth = scene.apparatus.type == ApparatusSpec::Type::Box ? scene.apparatus.size.z() : scene.apparatus.depth;
  const int k = int(std::floor((0.5 * depth - grid.origin.z()) / grid.spacing.z()));
  return std::clamp(k, 0, grid.shape[2] - 1);
}

std::vector<double> densityHistogram(const std::vector<double>& values, const std::vector<double>& weights,
                                     const std::vector<double>& edges) {
  const std::size_t bins = edges.size() - 1;
  std::vector<double> density(bins, 0.0);
  double total = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    const auto it = std::upper_bound(edges.begin(), edges.end(), values[i]);
    const std::size_t b = std::min<std::size_t>(bins - 1, std::size_t(std::max<std::ptrdiff_t>(1, it - edges.begin()) - 1));
    density[b] += w;
    total += w;
  }
  for (std::size_t b = 0; b < bins; ++b) {
    const double width = edges[b + 1] - edges[b];
    density[b] = total > 0.0 && width > 0.0 ? density[b] / (total * width) : 0.0;
  }
  return density;
}

nlohmann::json writeCalibrationReport(const CalibrationInputs& in, const std::string& resultPath,
                                      const std::string& figureDir) {
  const std::size_t n = in.d0.size();
  const double dt = in.scene.rcfd.dt;
  const CartesianGrid& grid = in.database.grid();
  const int layer = midplaneLayer(in.scene, grid);
  const auto fluidMid = [&] {
    const auto& f = in.database.fluidFraction();
    return slice(std::vector<float>(f.begin(), f.end()), grid, layer);
  }();
  const std::size_t probe = figureProbe(in.scene);
  const std::size_t probes = in.scene.probes.size();
  const bool refRtd = in.reference.hasDurations(), refHoldup = in.reference.hasHoldup();
  const double refHoldupMean = in.reference.holdupMean();
  // The members whose stays the reference counted: its own attribute, else the scene's real particles
  // (one member each, as the tracers' holdup is counted).
  const double refMembers = referenceMembers(in.reference, in.scene.process.bed_mass, in.scene.particles.density,
                                            in.scene.particles.diameter);
  const double tracerPeriod = double(in.steps - in.discardSteps) * dt;

  std::vector<D0Scores> scores(n);
  std::vector<RunData> runs(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string dir = in.runsDir + "/d0_" + std::to_string(i);
    const nlohmann::json rs = readJson(dir + "/summary.json");
    h5::File r(dir + "/result.h5", h5::File::Mode::ReadOnly);
    D0Scores& s = scores[i];
    RunData& d = runs[i];
    s.d0 = in.d0[i];
    s.penalty = rs.at("probes").at("penalty_mean").get<double>();
    s.rms = rs.at("probes").at("rms_mean").get<double>();
    s.fieldRms = rs.at("field_average").at("rms_difference").get<double>();
    s.holdupMean = rs.at("holdup").at("mean").get<double>();
    s.rtdMean = rs.at("residence_time").at("mean_s").get<double>();
    s.rtdMedian = rs.at("residence_time").at("median_s").get<double>();
    s.stays = rs.at("residence_time").at("stays").get<long long>();

    s.instantaneousRms = rs.at("field_average").at("instantaneous_rms_difference").get<double>();
    s.countingFloorRms = rs.at("field_average").at("counting_floor_rms").get<double>();
    d.durationCounts = r.readInt64s("/residence_time/duration_steps_counts");
    if (refRtd && s.stays > 0) {
      const StayComparison c = compareStays(d.durationCounts, dt, double(in.scene.rcfd.tracers), tracerPeriod,
                                            in.reference.durations, refMembers, in.reference.recordedPeriod());
      s.ksDistance = c.ksDistance;
      if (std::isfinite(c.meanError())) s.rtdMeanRelativeError = c.meanError();
      if (std::isfinite(c.crossingRateError())) s.crossingRateRelativeError = c.crossingRateError();
      s.staysJson = c.toJson();
    }
    if (refHoldup && refHoldupMean > 0.0) s.holdupRelativeError = (s.holdupMean - refHoldupMean) / refHoldupMean;
    if (in.reference.sampledPeriod && s.stays > 0) {
      s.sampledPeriodJson = compareWithPeriod(*in.reference.sampledPeriod, d.durationCounts, dt,
                                              double(in.scene.rcfd.tracers), tracerPeriod, s.holdupMean, refMembers);
    }

    // Mid-plane of the time averages, and their open-volume-weighted RMS difference there.
    d.midplane = slice(r.readFloats("/field_average/alpha_p_tracers"), grid, layer);
    d.recurrenceMidplane = slice(r.readFloats("/field_average/alpha_p_recurrence"), grid, layer);
    double diff2 = 0.0, weight = 0.0;
    for (std::size_t c = 0; c < d.midplane.size(); ++c) {
      const double e = double(d.midplane[c]) - double(d.recurrenceMidplane[c]);
      diff2 += double(fluidMid[c]) * e * e;
      weight += double(fluidMid[c]);
    }
    s.fieldRmsMidplane = weight > 0.0 ? std::sqrt(diff2 / weight) : 0.0;

    d.probeTime = r.readDoubles("/probes/time");
    d.probeTracerAll = r.readDoubles("/probes/alpha_p_tracers");
    d.probeRecurrenceAll = r.readDoubles("/probes/alpha_p_recurrence");
    for (std::size_t k = 0; k < d.probeTime.size(); ++k) {
      d.probeTracer.push_back(d.probeTracerAll[k * probes + probe]);
      d.probeRecurrence.push_back(d.probeRecurrenceAll[k * probes + probe]);
    }
    d.holdup = r.readDoubles("/holdup/particles");
    d.holdupDt = r.doubleAttribute("/holdup/particles", "dt");
    d.holdupT0 = r.doubleAttribute("/holdup/particles", "t0");
  }
  const Selection sel = selectD0(scores, in.options, refRtd);

  // Common residence-time bins for every run and the reference (Fig. 11).
  double longest = dt;
  for (const auto& d : runs) longest = std::max(longest, double(d.durationCounts.size()) * dt);
  for (const double t : in.reference.durations) longest = std::max(longest, t);
  const int bins = std::max(1, in.scene.outputs.residence_time_bins);
  std::vector<double> edges(std::size_t(bins) + 1);
  for (int b = 0; b <= bins; ++b) edges[std::size_t(b)] = longest * double(b) / double(bins);

  CalibrationFigureData fig;
  fig.d0 = in.d0;
  fig.selected = sel.selected;
  fig.penaltyMinimum = sel.penaltyMinimum;
  fig.probeName = in.scene.probes[probe].name;
  fig.nx = grid.shape[0];
  fig.ny = grid.shape[1];
  fig.x0 = grid.origin.x();
  fig.x1 = grid.origin.x() + grid.spacing.x() * grid.shape[0];
  fig.y0 = grid.origin.y();
  fig.y1 = grid.origin.y() + grid.spacing.y() * grid.shape[1];
  fig.recurrenceMidplane = runs[0].recurrenceMidplane;  // one path for all runs: the same average
  if (refHoldup) fig.referenceHoldup = in.reference.holdup, fig.referenceHoldupDt = in.reference.holdupDt;
  if (refRtd) {  // on the tracers' step lattice, as the scores compare it (StayComparison.hpp)
    const WeightedSample lattice = onStepLattice(in.reference.durations, dt);
    fig.referenceRtdDensity = densityHistogram(lattice.values, lattice.weights, edges);
  }
  fig.rtdEdges = edges;

  h5::File out(resultPath, h5::File::Mode::Create);
  out.writeString("/scene", in.scene.source_json);
  auto column = [&](auto get) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = get(scores[i]);
    return v;
  };
  out.write("/calibration/d0", in.d0);
  out.write("/calibration/penalty", column([](const D0Scores& s) { return s.penalty; }));
  out.write("/calibration/rms", column([](const D0Scores& s) { return s.rms; }));
  out.write("/calibration/field_rms_difference", column([](const D0Scores& s) { return s.fieldRms; }));
  out.write("/calibration/field_rms_difference_midplane", column([](const D0Scores& s) { return s.fieldRmsMidplane; }));
  out.write("/calibration/holdup_mean", column([](const D0Scores& s) { return s.holdupMean; }));
  out.write("/calibration/residence_time_mean_s", column([](const D0Scores& s) { return s.rtdMean; }));
  out.write("/calibration/residence_time_median_s", column([](const D0Scores& s) { return s.rtdMedian; }));
  out.write("/calibration/rtd_ks_distance", column([](const D0Scores& s) { return s.ksDistance.value_or(kNaN); }));
  out.write("/calibration/rms_over_floor", column([](const D0Scores& s) { return s.rmsOverFloor(); }));
  out.write("/calibration/residence_time_mean_relative_error",
            column([](const D0Scores& s) { return s.rtdMeanRelativeError.value_or(kNaN); }));
  out.write("/calibration/crossing_rate_relative_error",
            column([](const D0Scores& s) { return s.crossingRateRelativeError.value_or(kNaN); }));
  out.write("/calibration/holdup_relative_error",
            column([](const D0Scores& s) { return s.holdupRelativeError.value_or(kNaN); }));
  out.setAttribute("/calibration", "selected_d0", scores[sel.selected].d0);
  out.setAttribute("/calibration", "penalty_minimum_d0", scores[sel.penaltyMinimum].d0);
  out.setAttribute("/calibration", "selection_reason", sel.reason);
  out.write("/calibration/rtd_edges", edges);
  const std::vector<hsize_t> planeShape{hsize_t(grid.shape[1]), hsize_t(grid.shape[0])};
  out.write("/calibration/recurrence/alpha_p_midplane", fig.recurrenceMidplane, planeShape);
  if (refHoldup) {
    out.write("/calibration/reference/holdup_particles", in.reference.holdup);
    out.setAttribute("/calibration/reference/holdup_particles", "dt", in.reference.holdupDt);
  }
  if (refRtd) out.write("/calibration/reference/rtd_density", fig.referenceRtdDensity);
  for (std::size_t i = 0; i < n; ++i) {
    const RunData& d = runs[i];
    const std::string g = "/calibration/runs/d0_" + std::to_string(i);
    const hsize_t rows = d.probeTime.size();
    out.write(g + "/probes/time", d.probeTime);
    out.write(g + "/probes/alpha_p_tracers", d.probeTracerAll, {rows, hsize_t(probes)});
    out.write(g + "/probes/alpha_p_recurrence", d.probeRecurrenceAll, {rows, hsize_t(probes)});
    out.write(g + "/holdup/particles", d.holdup);
    out.setAttribute(g + "/holdup/particles", "dt", d.holdupDt);
    out.setAttribute(g + "/holdup/particles", "t0", d.holdupT0);
    out.write(g + "/residence_time/duration_steps_counts", d.durationCounts);
    std::vector<double> values, weights;
    for (std::size_t k = 0; k < d.durationCounts.size(); ++k) {
      values.push_back(double(k) * dt);
      weights.push_back(double(d.durationCounts[k]));
    }
    fig.rtdDensity.push_back(densityHistogram(values, weights, edges));
    out.write(g + "/residence_time/density", fig.rtdDensity.back());
    out.write(g + "/field_average/alpha_p_midplane", d.midplane, planeShape);
    out.setAttribute(g, "d0", in.d0[i]);
    fig.penalty.push_back(scores[i].penalty);
    fig.probeTime.push_back(d.probeTime);
    fig.probeTracer.push_back(d.probeTracer);
    fig.probeRecurrence.push_back(d.probeRecurrence);
    fig.holdup.push_back(d.holdup);
    fig.holdupDt = d.holdupDt;
    fig.holdupT0 = d.holdupT0;
    // Cells outside the apparatus stay blank in the maps.
    std::vector<float> shown = d.midplane;
    for (std::size_t c = 0; c < shown.size(); ++c)
      if (!(fluidMid[c] > 0.0f)) shown[c] = std::numeric_limits<float>::quiet_NaN();
    fig.midplane.push_back(std::move(shown));
  }
  for (std::size_t c = 0; c < fig.recurrenceMidplane.size(); ++c)
    if (!(fluidMid[c] > 0.0f)) fig.recurrenceMidplane[c] = std::numeric_limits<float>::quiet_NaN();
  out.flush();

  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < n; ++i) {
    const D0Scores& s = scores[i];
    list.push_back({{"value", s.d0},
                    {"penalty", s.penalty},
                    {"rms", s.rms},
                    {"holdup_mean", s.holdupMean},
                    {"holdup_relative_error", optionalNumber(s.holdupRelativeError)},
                    {"residence_time_mean_s", s.rtdMean},
                    {"residence_time_median_s", s.rtdMedian},
                    {"stays", s.stays},
                    {"rtd_ks_distance", optionalNumber(s.ksDistance)},
                    {"residence_time_mean_relative_error", optionalNumber(s.rtdMeanRelativeError)},
                    {"crossing_rate_relative_error", optionalNumber(s.crossingRateRelativeError)},
                    {"instantaneous_rms_difference", s.instantaneousRms},
                    {"counting_floor_rms", s.countingFloorRms},
                    {"rms_over_floor", s.rmsOverFloor()},
                    {"stay_comparison", s.staysJson},
                    {"against_sampled_period", s.sampledPeriodJson},
                    {"field_rms_difference", s.fieldRms},
                    {"field_rms_difference_midplane", s.fieldRmsMidplane},
                    {"bed_shape_agrees", bool(sel.bedShapeAgrees[i])},
                    {"residence_times_agree", bool(sel.residenceTimesAgree[i])}});
  }
  std::vector<std::string> notComputed;
  if (!refRtd) notComputed.push_back("rtd_ks_distance");
  if (!refHoldup) notComputed.push_back("holdup_relative_error");
  for (const auto& name : notComputed) {
    spdlog::warn("calibration: {} not computed: the database has no reference statistics for it", name);
  }
  nlohmann::json reference = {{"available", in.reference.missing.empty()},
                              {"missing", in.reference.missing},
                              {"scores_not_computed", notComputed}};
  if (!in.reference.zoneMismatch.empty()) reference["zone_mismatch"] = in.reference.zoneMismatch;
  if (refRtd) {
    double sum = 0.0;
    for (const double t : in.reference.durations) sum += t;
    reference["residence_time_mean_s"] = sum / double(in.reference.durations.size());
    reference["residence_time_median_s"] = median(in.reference.durations);
    reference["stays"] = in.reference.durations.size();
    reference["members"] = refMembers;
    reference["members_from"] = in.reference.members > 0.0 ? "database" : "scene (bed mass / particle mass)";
    reference["period_s"] = in.reference.recordedPeriod();
    reference["residence_time_mean_on_tracer_lattice_s"] =
        summariseStays(onStepLattice(in.reference.durations, dt), refMembers, in.reference.recordedPeriod()).mean_s;
  }
  if (refHoldup) reference["holdup_mean"] = refHoldupMean;
  if (const auto& sampled = in.reference.sampledPeriod) {
    // The full simulation against itself: its sampled period (the frames') against the reference period.
    const double sampledHoldup = sampled->holdupMean();
    reference["sampled_period"] = {
        {"period_s", sampled->recordedPeriod()},
        {"holdup_mean", sampled->hasHoldup() ? nlohmann::json(sampledHoldup) : nlohmann::json()},
        {"holdup_over_reference",
         refHoldup && refHoldupMean > 0.0 && sampled->hasHoldup() ? nlohmann::json(sampledHoldup / refHoldupMean)
                                                                  : nlohmann::json()},
        {"stays", sampled->durations.size()}};
  }
  // What the recurrence field itself holds in the zone over the runs' collected steps (one path for all
  // runs: the same average), beside the parcel centres the reference counts (docs/calibration.md).
  {
    h5::File r(in.runsDir + "/d0_0/result.h5", h5::File::Mode::ReadOnly);
    const double field = fieldHoldup(in.scene, grid, r.readFloats("/field_average/alpha_p_recurrence"),
                                     in.database.fluidFraction());
    reference["recurrence_field_holdup"] = field;
    if (refHoldup && refHoldupMean > 0.0) reference["recurrence_field_holdup_over_reference"] = field / refHoldupMean;
  }

  nlohmann::json summary = {{"d0", list},
                            {"selected_d0", scores[sel.selected].d0},
                            {"penalty_minimum_d0", scores[sel.penaltyMinimum].d0},
                            {"selection_reason", sel.reason},
                            {"selection",
                             {{"rule_satisfied", sel.ruleSatisfied},
                              {"field_rms_tolerance", in.options.fieldRmsTolerance},
                              {"ks_threshold", in.options.ksThreshold},
                              {"rtd_relative_tolerance", in.options.rtdRelativeTolerance},
                              {"extend_sweep", in.options.extendSweep},
                              {"at_upper_end", sel.atUpperEnd},
                              {"residence_times_judged_by", refRtd ? "ks_mean_and_crossing_rate_on_the_tracer_lattice" : "mean_relative_tolerance"}}},
                            {"reference", reference},
                            {"probe_of_figure", fig.probeName},
                            {"midplane_layer", layer}};
  if (!figureDir.empty()) summary["figures"] = writeCalibrationFigures(fig, figureDir);
  return summary;
}

}  // namespace rcfd::analysis
