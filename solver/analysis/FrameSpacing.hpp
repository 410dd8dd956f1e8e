#pragma once
/// \file FrameSpacing.hpp
/// How far the particles in the spray zone move between two frames of a database, in cells.
///
/// Between two frames the tracers move in a held frame (or a blend of two): a flow that moves several
/// cells between frames is seen frozen, and the tracers' spray-zone stays come out long and their
/// crossings rare whatever D0 and the rCFD step. On the dilute jet (docs/accuracy.md, "Between
/// frames") the stays were 5 % long at 0.8 cells per frame, 7 % at 1.6, 10 % at 3.2 and 30 % at 9.6
/// (the particle-volume-weighted median speed in the zone times dt_rec, over the cell edge).

#include <nlohmann/json.hpp>

#include "fields/FieldDatabase.hpp"
#include "geometry/SprayZone.hpp"

namespace rcfd {

/// Cells per frame above which a job warns that its database is sampled too sparsely.
inline constexpr double kSparseCellsPerFrame = 2.0;

struct FrameSpacing {
  double dtRec = 0.0;            ///< the database's interval [s]
  double medianSpeed = 0.0;      ///< median |u_P| in the zone's cells, weighted by particle volume [m/s]
  double p90Speed = 0.0;         ///< its 90th percentile [m/s]
  double cellsPerFrame = 0.0;    ///< medianSpeed dt_rec / the smallest cell edge [-]
  int framesSampled = 0;
  std::int64_t zoneCells = 0;    ///< cells whose centre lies in the zone
  bool sparse() const { return cellsPerFrame > kSparseCellsPerFrame; }
};

/// Over up to `maxFrames` frames spread evenly over the database, the cells whose centre lies in
/// `zone`. A zone without particle volume in any sampled frame gives speeds and cells per frame 0.
FrameSpacing frameSpacing(const FieldDatabase& database, const SprayZone& zone, int maxFrames = 50);

nlohmann::json toJson(const FrameSpacing& spacing);

/// The warning a job logs for a sparse database (empty when it is not sparse).
std::string sparseFramesWarning(const FrameSpacing& spacing);

}  // namespace rcfd
