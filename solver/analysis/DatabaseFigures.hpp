#pragma once
/// \file DatabaseFigures.hpp
/// The database job's SVG figures: alpha_P on the mid-plane z = depth / 2 at a few sampled instants
/// and averaged over all frames, each with the apparatus outline (walls, inlet, outlet, draft plates),
/// and the bed pressure-drop series with its mean and dominant frequency.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fields/FieldDatabase.hpp"
#include "scene/Scene.hpp"

namespace rcfd::analysis {

/// alpha_P averaged over every frame of the database, per cell (x fastest) [-]. `stopRequested` is
/// polled before each frame (a long database takes minutes to read); true throws rcfd::Cancelled.
std::vector<double> meanAlphaP(const FieldDatabase& db, const std::function<bool()>& stopRequested = {});

/// Frames shown as snapshots: `count` instants evenly spread over the database, first and last
/// included (fewer when the database has fewer frames).
std::vector<int> snapshotFrames(int frameCount, int count = 4);

struct PressureDropSeries {
  std::vector<double> pa;   ///< pressure drop samples [Pa]
  double dt = 0.0;          ///< sampling interval [s]
  double t0 = 0.0;          ///< time of the first sample after the start of sampling [s]
  std::optional<double> dominantFrequency;  ///< [Hz]
};

/// Writes database_alpha_p.svg (snapshots and the time average) and, when the series is not empty,
/// database_pressure_drop.svg into outDir; returns the file names written. `stopRequested` as in
/// meanAlphaP.
std::vector<std::string> writeDatabaseFigures(const Scene& scene, const FieldDatabase& db,
                                              const PressureDropSeries& pressureDrop, const std::string& outDir,
                                              const std::function<bool()>& stopRequested = {});

}  // namespace rcfd::analysis
