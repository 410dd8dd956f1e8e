#include "analysis/CalibrationSelection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "core/Errors.hpp"

namespace rcfd::analysis {
namespace {

std::string g3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

double option(const nlohmann::json& c, const char* key, double fallback, double lo, double hi, bool loOpen) {
  if (!c.contains(key)) return fallback;
  const std::string pointer = std::string("/calibration/") + key;
  const auto& v = c.at(key);
  if (!v.is_number()) throw InputError("job", pointer, "must be a number");
  const double x = v.get<double>();
  const bool ok = std::isfinite(x) && (loOpen ? x > lo : x >= lo) && x <= hi;
  if (!ok) {
    throw InputError("job", pointer, g3(x) + " is outside " + (loOpen ? "(" : "[") + g3(lo) + ", " + g3(hi) + "]");
  }
  return x;
}

}  // namespace

SelectionOptions selectionOptionsFrom(const nlohmann::json& job) {
  SelectionOptions o;
  if (!job.is_object() || !job.contains("calibration")) return o;
  const auto& c = job.at("calibration");
  if (!c.is_object()) throw InputError("job", "/calibration", "must be an object");
  o.fieldRmsTolerance = option(c, "field_rms_tolerance", o.fieldRmsTolerance, 0.0, 10.0, false);
  o.ksThreshold = option(c, "ks_threshold", o.ksThreshold, 0.0, 1.0, true);
  o.rtdRelativeTolerance = option(c, "rtd_relative_tolerance", o.rtdRelativeTolerance, 0.0, 10.0, true);
  if (c.contains("extend_sweep")) {
    if (!c.at("extend_sweep").is_boolean()) throw InputError("job", "/calibration/extend_sweep", "must be true or false");
    o.extendSweep = c.at("extend_sweep").get<bool>();
  }
  o.sweepFactor = option(c, "sweep_factor", o.sweepFactor, 1.0, 100.0, true);
  return o;
}

Selection selectD0(const std::vector<D0Scores>& s, const SelectionOptions& o, bool useReference) {
  if (s.empty()) throw std::invalid_argument("selectD0: no scores");
  const std::size_t n = s.size();
  // Visit D0 values in ascending order (the job file may list them in any order).
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return s[a].d0 < s[b].d0; });

  Selection sel;
  sel.penaltyMinimum = order[0];
  std::size_t bestShape = order[0];
  for (const std::size_t i : order) {
    if (s[i].penalty < s[sel.penaltyMinimum].penalty) sel.penaltyMinimum = i;
    if (s[i].rmsOverFloor() < s[bestShape].rmsOverFloor()) bestShape = i;
  }
  const double shapeLimit = 1.0 + o.fieldRmsTolerance;
  const double rtdTarget = s[bestShape].rtdMean;
  auto within = [&](const std::optional<double>& e) { return e && std::abs(*e) <= o.rtdRelativeTolerance; };
  sel.bedShapeAgrees.assign(n, false);
  sel.residenceTimesAgree.assign(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    sel.bedShapeAgrees[i] = s[i].countingFloorRms > 0.0 && s[i].rmsOverFloor() <= shapeLimit;
    if (s[i].stays == 0) continue;  // no completed stay: no residence-time distribution to compare
    if (useReference) {
      sel.residenceTimesAgree[i] = s[i].ksDistance && *s[i].ksDistance <= o.ksThreshold &&
                                   within(s[i].rtdMeanRelativeError) &&
                                   (!s[i].crossingRateRelativeError || within(s[i].crossingRateRelativeError));
    } else {
      sel.residenceTimesAgree[i] = rtdTarget > 0.0 && std::abs(s[i].rtdMean - rtdTarget) <= o.rtdRelativeTolerance * rtdTarget;
    }
  }
  const std::string bed = "bed shape (instantaneous alpha_P RMS within " + g3(shapeLimit) +
                          " x its counting floor)";
  const std::string rtd =
      useReference ? "residence times (KS distance <= " + g3(o.ksThreshold) + ", mean stay and crossing rate within " +
                         g3(100.0 * o.rtdRelativeTolerance) + "% of the reference)"
                   : "residence times (mean within " + g3(100.0 * o.rtdRelativeTolerance) + "% of the best-shaped run's " +
                         g3(rtdTarget) + " s; no reference RTD)";
  const std::string penalty = "; the penalty minimum is at D0 = " + g3(s[sel.penaltyMinimum].d0) + " m2/s";
  auto scores = [&](std::size_t i) {
    std::string t = "RMS/floor " + g3(s[i].rmsOverFloor());
    if (s[i].ksDistance) t += ", KS " + g3(*s[i].ksDistance);
    if (s[i].rtdMeanRelativeError) t += ", mean stay " + g3(100.0 * *s[i].rtdMeanRelativeError) + "%";
    if (s[i].crossingRateRelativeError) t += ", crossing rate " + g3(100.0 * *s[i].crossingRateRelativeError) + "%";
    return t;
  };
  const std::size_t top = order.back();
  bool found = false;
  for (const std::size_t i : order) {
    if (sel.bedShapeAgrees[i] && sel.residenceTimesAgree[i]) {
      sel.selected = i;
      sel.ruleSatisfied = true;
      sel.reason = "D0 = " + g3(s[i].d0) + " m2/s is the lowest value whose " + bed + " and " + rtd + " agree (" +
                   scores(i) + ")" + penalty;
      found = true;
      break;
    }
  }
  if (!found) {
    // No D0 met both. Where some bed shape agrees, the paper's order holds: the lowest such D0. Where
    // none does, the bed shape cannot tell a viable D0 from another, and the residence times, on which
    // the coverage rests, decide: the best-shaped D0 among those whose residence times agree, else the
    // best-shaped of all.
    std::optional<std::size_t> lowestShaped, bestShapedAgreeing;
    for (const std::size_t i : order) {
      if (sel.bedShapeAgrees[i] && !lowestShaped) lowestShaped = i;
      if (sel.residenceTimesAgree[i] &&
          (!bestShapedAgreeing || s[i].rmsOverFloor() < s[*bestShapedAgreeing].rmsOverFloor())) {
        bestShapedAgreeing = i;
      }
    }
    std::string why;
    if (lowestShaped) {
      sel.selected = *lowestShaped;
      why = "lowest whose " + bed + " agrees";
    } else if (bestShapedAgreeing) {
      sel.selected = *bestShapedAgreeing;
      why = "one with the best bed shape among those whose residence times agree (no bed shape does)";
    } else {
      sel.selected = bestShape;
      why = "one with the best bed shape";
    }
    // Name the values that met the residence-time criterion alone, if any: they are what a wider
    // tolerance or more tracers (a lower counting floor) would select.
    std::string rtdOnly;
    for (const std::size_t i : order) {
      if (sel.residenceTimesAgree[i]) rtdOnly += (rtdOnly.empty() ? "" : ", ") + g3(s[i].d0);
    }
    const std::string rtdClause = rtdOnly.empty()
        ? ", and no value met the " + rtd + " criterion"
        : "; the " + rtd + " agree at D0 = " + rtdOnly + " m2/s, whose bed shape does not";
    sel.reason = "no D0 met both criteria; D0 = " + g3(s[sel.selected].d0) + " m2/s is the " + why + " (" +
                 scores(sel.selected) + ")" + rtdClause + penalty;
  }
  sel.atUpperEnd = n > 1 && (sel.selected == top || sel.penaltyMinimum == top);
  return sel;
}

}  // namespace rcfd::analysis
