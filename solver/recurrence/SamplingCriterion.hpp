#pragma once
/// \file SamplingCriterion.hpp
/// The temporal resolution criterion of Eq. (8): dt_rec < sqrt(<gamma^2> / <gamma_dot^2>) for a field
/// gamma, with <.> the time average over the frames and gamma_dot by central differences
/// (gamma_{n+1} - gamma_{n-1}) / (2 dt_rec) on the interior frames 1..N-2 (both averages use those
/// frames). As in the paper, the mean is not subtracted: <gamma^2> is the mean square, not the
/// variance. Evaluated at probe points (the cell containing each point) or over every open cell.
///
/// Caveat: computed from the frames themselves, central differences cannot see content faster than
/// the sampling (it aliases), and |gamma_dot| <= 2 max|gamma| / (2 dt) keeps the bound near or above
/// dt_rec; a bound close to dt_rec means "not resolved". A conclusive check uses a signal sampled
/// faster than dt_rec (samplingBound() on a CFD-DEM probe series, as in the paper's Fig. 5).

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "fields/FieldDatabase.hpp"

namespace rcfd {

struct SamplingProbe {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< [m]
};

/// Eq. (8) at one probe or cell.
struct SamplingPoint {
  std::string name;              ///< probe name, or "cell (i, j, k)"
  std::array<int, 3> cell{0, 0, 0};
  double rms = 0.0;              ///< sqrt(<gamma^2>) [field unit]
  double rateRms = 0.0;          ///< sqrt(<gamma_dot^2>) [field unit / s]
  double bound = 0.0;            ///< sqrt(<gamma^2>/<gamma_dot^2>) [s]; +inf if gamma never changes
};

struct SamplingReport {
  std::string field;             ///< e.g. "u_p.y"
  double dtRec = 0.0;            ///< the database's sampling interval [s]
  bool allCells = false;         ///< over every open cell instead of probes
  std::vector<SamplingPoint> points;  ///< per probe (probe mode only)
  SamplingPoint strictest;       ///< the point with the smallest bound
  double largestAdmissibleDtRec = 0.0;  ///< min bound over the points [s]
  bool satisfied = false;        ///< dtRec < largestAdmissibleDtRec
  std::int64_t pointsConsidered = 0;
  std::int64_t pointsWithoutVariation = 0;  ///< gamma constant in time: no bound (skipped)
  double medianBound = 0.0;      ///< all-cells mode: median of the finite bounds [s]
};

/// Eq. (8) for `field` ("alpha_p", "u_p.x", ..., "u_g.z") at `probes`, or over every open cell if
/// `probes` is empty. rcfd::InputError for an unknown field or a probe outside the grid.
SamplingReport samplingCriterion(const FieldDatabase& db, const std::string& field = "u_p.y",
                                 const std::vector<SamplingProbe>& probes = {});

/// Eq. (8) for one time series gamma_n sampled every dt [s] (e.g. a CFD-DEM probe signal sampled
/// faster than the fields): sqrt(<gamma^2>/<gamma_dot^2>) over the interior samples, central
/// differences; +inf if gamma never changes. rcfd::InputError for fewer than 3 samples or dt <= 0.
double samplingBound(const std::vector<double>& gamma, double dt);

/// The scene's probes ({"probes": [{"name": ..., "position": [x, y, z]}]}); none if the JSON has no
/// such list or is not JSON.
std::vector<SamplingProbe> probesFromSceneJson(const std::string& sceneJson);

}  // namespace rcfd
