#pragma once
/// \file AnalyticDatabase.hpp
/// Databases from formulas, for tests and benchmarks of every area: the caller fills frame n (time
/// t = n dt_rec) and the database is written through FieldDatabaseWriter (or kept in memory), so it
/// is exactly what the CFD-DEM would produce.
///
///   writeAnalyticDatabase("db.h5", grid, fluid, 0.005, 200, [&](int n, double t, FieldFrame& f) {
///     for (std::int64_t c = 0; c < grid.cellCount(); ++c) f.alpha_p[c] = 0.3f + 0.1f * std::sin(t);
///   });

#include <functional>
#include <memory>
#include <string>

#include "fields/FieldDatabase.hpp"

namespace rcfd {

/// Fills `frame` for frame `n` at time `t` = n dt_rec [s]. The vectors arrive sized (cells, 3 cells,
/// 3 cells) and zeroed.
using FrameFunction = std::function<void(int n, double t, FieldFrame& frame)>;

/// Writes a database of `frames` frames to `path`; returns the number of frames written.
int writeAnalyticDatabase(const std::string& path, const CartesianGrid& grid,
                          const std::vector<float>& fluidFraction, double dtRec, int frames,
                          const FrameFunction& fill, const std::string& sceneJson = "{}",
                          FieldDatabaseWriterOptions options = {});

/// The same database held in memory (makeInMemoryDatabase).
std::shared_ptr<FieldDatabase> makeAnalyticDatabase(const CartesianGrid& grid,
                                                    const std::vector<float>& fluidFraction,
                                                    double dtRec, int frames, const FrameFunction& fill,
                                                    const std::string& sceneJson = "{}");

/// A zeroed frame sized for `grid`.
FieldFrame makeFrame(const CartesianGrid& grid);

}  // namespace rcfd
