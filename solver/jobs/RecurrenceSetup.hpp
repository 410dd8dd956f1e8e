#pragma once
/// \file RecurrenceSetup.hpp
/// What calibration and spray jobs share before their tracers move: the database opened with the
/// scene's frame storage, its recurrence matrix (read from the file when stored, computed and stored
/// otherwise) and the recurrence path the scene asks for.

#include <functional>
#include <memory>

#include "fields/FieldDatabase.hpp"
#include "recurrence/RecurrenceMatrix.hpp"
#include "recurrence/RecurrencePath.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

struct RecurrenceSetup {
  std::shared_ptr<FieldDatabase> database;
  RecurrenceMatrix matrix;
  RecurrencePath path;
  PathStatistics pathStats;
  bool matrixWasStored = false;  ///< read from /recurrence/matrix instead of computed
};

/// Opens `databasePath`, gets its recurrence matrix and builds a path of at least `frames` entries.
/// `stopRequested` is polled (from several threads) between the frames read and the matrix's tiles:
/// true ends the setup with rcfd::Cancelled, leaving the database file as it was.
RecurrenceSetup prepareRecurrence(const Scene& scene, const std::string& databasePath, std::int64_t frames,
                                  std::uint64_t seed, const std::function<bool()>& stopRequested = {});

/// The path of the scene's generator through `matrix`, of at least `frames` entries, for `seed`, and
/// its statistics: what prepareRecurrence builds for its seed (an ensemble's further members draw
/// theirs with it from the one matrix). InputError for an unknown generator.
RecurrencePath generateRecurrencePath(const Scene& scene, const RecurrenceMatrix& matrix, std::int64_t frames,
                                      std::uint64_t seed, PathStatistics* statistics = nullptr);

}  // namespace rcfd
