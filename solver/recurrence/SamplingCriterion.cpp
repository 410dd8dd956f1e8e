#include "recurrence/SamplingCriterion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/Errors.hpp"
#include "recurrence/RecurrenceMatrix.hpp"

namespace rcfd {

SamplingReport samplingCriterion(const FieldDatabase& db, const std::string& fieldName,
                                 const std::vector<SamplingProbe>& probes) {
  const FieldComponent field = parseFieldComponent(fieldName, "--sampling-field");
  const CartesianGrid& grid = db.grid();
  SamplingReport report;
  report.field = fieldName;
  report.dtRec = db.dtRec();
  report.allCells = probes.empty();

  std::vector<std::int64_t> cells;
  std::vector<std::string> names;
  if (report.allCells) {
    const auto& fluid = db.fluidFraction();
    for (std::size_t c = 0; c < fluid.size(); ++c)
      if (fluid[c] > 0.0f) cells.push_back(std::int64_t(c));
  } else {
    const Eigen::Vector3d lo = grid.origin, hi = grid.upperCorner();
    for (std::size_t p = 0; p < probes.size(); ++p) {
      const Eigen::Vector3d& x = probes[p].position;
      if (!x.allFinite() || (x.array() < lo.array()).any() || (x.array() > hi.array()).any()) {
        throw InputError("sampling criterion", "/probes/" + std::to_string(p) + "/position",
                         "(" + std::to_string(x.x()) + ", " + std::to_string(x.y()) + ", " +
                             std::to_string(x.z()) + ") lies outside the database grid");
      }
      cells.push_back(grid.flatIndexOf(x));
      names.push_back(probes[p].name.empty() ? "probe " + std::to_string(p + 1) : probes[p].name);
    }
  }

  const int n = db.frameCount();
  const double dt = db.dtRec();
  const std::int64_t m = std::int64_t(cells.size());
  std::vector<double> sumSquare(std::size_t(m), 0.0), sumRateSquare(std::size_t(m), 0.0);
  auto previous = db.frame(0), current = db.frame(1);
  for (int k = 1; k + 1 < n; ++k) {
    const auto next = db.frame(k + 1);
    // Serial on purpose: a few flops per cell and frame (0.2 s for 2000 x 73,647) do not pay for an
    // OpenMP region per frame when the cores are shared.
    for (std::int64_t i = 0; i < m; ++i) {
      const double g = field.value(*current, cells[std::size_t(i)]);
      // Central difference of gamma in time.
      const double rate = (double(field.value(*next, cells[std::size_t(i)])) -
                           double(field.value(*previous, cells[std::size_t(i)]))) / (2.0 * dt);
      sumSquare[std::size_t(i)] += g * g;
      sumRateSquare[std::size_t(i)] += rate * rate;
    }
    previous = current;
    current = next;
  }

  const double samples = double(n - 2);
  std::vector<double> finiteBounds;
  report.largestAdmissibleDtRec = std::numeric_limits<double>::infinity();
  report.strictest.bound = std::numeric_limits<double>::infinity();
  for (std::int64_t i = 0; i < m; ++i) {
    SamplingPoint point;
    point.cell = grid.cellIjk(cells[std::size_t(i)]);
    point.name = report.allCells ? "cell (" + std::to_string(point.cell[0]) + ", " +
                                       std::to_string(point.cell[1]) + ", " +
                                       std::to_string(point.cell[2]) + ")"
                                 : names[std::size_t(i)];
    point.rms = std::sqrt(sumSquare[std::size_t(i)] / samples);
    point.rateRms = std::sqrt(sumRateSquare[std::size_t(i)] / samples);
    point.bound = point.rateRms > 0.0 ? point.rms / point.rateRms  // Eq. (8)
                                      : std::numeric_limits<double>::infinity();
    ++report.pointsConsidered;
    if (std::isfinite(point.bound)) finiteBounds.push_back(point.bound);
    else ++report.pointsWithoutVariation;
    if (point.bound < report.strictest.bound) report.strictest = point;
    if (!report.allCells) report.points.push_back(point);
  }
  report.largestAdmissibleDtRec = report.strictest.bound;
  report.satisfied = report.dtRec < report.largestAdmissibleDtRec;
  if (!finiteBounds.empty()) {
    const auto mid = finiteBounds.begin() + std::ptrdiff_t(finiteBounds.size() / 2);
    std::nth_element(finiteBounds.begin(), mid, finiteBounds.end());
    report.medianBound = *mid;
  } else {
    report.medianBound = std::numeric_limits<double>::infinity();
  }
  return report;
}

double samplingBound(const std::vector<double>& gamma, double dt) {
  if (gamma.size() < 3) {
    throw InputError("sampling criterion", "gamma", std::to_string(gamma.size()) + " samples; at least 3 are needed");
  }
  if (!(std::isfinite(dt) && dt > 0.0)) {
    throw InputError("sampling criterion", "dt", std::to_string(dt) + " must be finite and > 0 [s]");
  }
  double square = 0.0, rateSquare = 0.0;
  for (std::size_t n = 1; n + 1 < gamma.size(); ++n) {
    const double rate = (gamma[n + 1] - gamma[n - 1]) / (2.0 * dt);
    square += gamma[n] * gamma[n];
    rateSquare += rate * rate;
  }
  return rateSquare > 0.0 ? std::sqrt(square / rateSquare) : std::numeric_limits<double>::infinity();  // Eq. (8)
}

std::vector<SamplingProbe> probesFromSceneJson(const std::string& sceneJson) {
  std::vector<SamplingProbe> out;
  const auto doc = nlohmann::json::parse(sceneJson, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("probes") || !doc["probes"].is_array()) return out;
  for (const auto& p : doc["probes"]) {
    if (!p.is_object() || !p.contains("position")) continue;
    const auto& x = p["position"];
    if (!x.is_array() || x.size() != 3 || !x[0].is_number() || !x[1].is_number() || !x[2].is_number()) continue;
    SamplingProbe probe;
    probe.name = p.contains("name") && p["name"].is_string() ? p["name"].get<std::string>() : "";
    probe.position = Eigen::Vector3d(x[0].get<double>(), x[1].get<double>(), x[2].get<double>());
    out.push_back(probe);
  }
  return out;
}

}  // namespace rcfd
