#pragma once
/// \file DropletPaths.hpp
/// Where the full simulation's bed catches the spray: droplet paths launched at the nozzle as the spray
/// effect launches its parcels, carried by u_G through the database's frames in their own order (the
/// full simulation's time, not a recurrence path), each losing the fraction Eq. (11)-(14) gives for
/// every sub-step, with alpha_P and u_P of the frames. A path ends at the outlet or a wall (overspray,
/// as for the spray's parcels) or after a time limit (held). Reported: the shares of the droplets that
/// leave through the outlet, reach a wall, stay airborne and deposit; the share deposited before a path
/// first reaches each of a list of heights; and the optical depth -ln(survival) accumulated on the way
/// there. It tells which part of the bed holds the droplets back (the spray zone, the upper spout, the
/// fountain) and how much of the overspray comes from instants when the spout is open.
///
/// It answers for the bed the database holds, not for rCFD's tracers: the spray job deposits on the
/// tracers' alpha_P along a recurrence path. Deterministic for a seed, whatever the thread count.

#include <cstdint>
#include <vector>

#include "fields/FieldDatabase.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

struct DropletPathOptions {
  int launches = 64;            ///< launch instants, evenly spread over the frames that leave maxSeconds after them
  int pathsPerLaunch = 64;      ///< paths from each instant
  double maxSeconds = 1.0;      ///< a path still airborne after this counts as held [s]
  std::vector<double> heights;  ///< heights y at which the deposit and the optical depth are reported [m]
  std::uint64_t seed = 1;
};

struct DropletPathHeight {
  double y = 0.0;                ///< [m]
  double reached = 0.0;          ///< share of the paths that reach y
  double depositedBelow = 0.0;   ///< share of all droplets deposited before their path first reaches y
  double opticalDepthP10 = 0.0;  ///< -ln(survival) on first reaching y, over the paths that reach it
  double opticalDepthMedian = 0.0;
  double opticalDepthP90 = 0.0;
};

struct DropletPathReport {
  int launches = 0;
  int pathsPerLaunch = 0;
  double maxSeconds = 0.0;
  /// Shares of the launched droplets; they add up to 1.
  double outlet = 0.0;     ///< leave through the outlet
  double wall = 0.0;       ///< reach a wall, plate or the inlet
  double airborne = 0.0;   ///< still in flight after maxSeconds
  double deposited = 0.0;  ///< deposited on the bed
  /// Overspray (outlet + wall) of the launches, one per instant: how it is spread over time.
  double launchOversprayMedian = 0.0;
  double launchOversprayP90 = 0.0;
  double launchOversprayMax = 0.0;
  double launchesAbove1e3 = 0.0;  ///< share of the launches with an overspray above 1e-3
  std::vector<DropletPathHeight> heights;
};

/// rcfd::InputError naming the option when the database is too short for maxSeconds or an option is
/// out of range (at most 1,000,000 paths in all and 100 heights).
DropletPathReport dropletPaths(const Scene& scene, const FieldDatabase& db, const DropletPathOptions& options);

}  // namespace rcfd
