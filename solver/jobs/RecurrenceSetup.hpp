#pragma once
/// \file RecurrenceSetup.hpp
/// What calibration and spray jobs share before their tracers move: the database opened with the
/// scene's frame storage, its recurrence matrix (read from the file when stored, computed and stored
/// otherwise) and the recurrence path the scene asks for.

#include <algorithm>
#include <functional>
#include <memory>

#include "analysis/FrameSpacing.hpp"
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
  FrameSpacing frameSpacing;     ///< how far the spray zone's particles move between two frames
};

/// What prepareRecurrence() has to do for a database and its expected work, in tracer steps (one
/// tracer moved by one step): what the calibration and spray jobs weigh their "recurrence" phase by
/// against their tracer runs, so that their progress grows about linearly in wall time.
struct RecurrenceWork {
  int frames = 0;
  std::int64_t cells = 0;
  bool readIntoMemory = false;  ///< rcfd.frame_cache_bytes 0: every frame is read at the open
  bool matrixStored = false;    ///< /recurrence/matrix holds the matrix: nothing to compute
  /// Reading the frames into memory [tracer steps]: twice when the matrix is computed (the file is
  /// closed while the matrix is stored into it).
  double read = 0.0;
  double matrix = 0.0;          ///< computing the matrix [tracer steps]
  double total() const { return read + matrix; }
};

/// Tracer steps one cell of one frame costs to read from the file into memory (7 to 17 floats, checked
/// for NaN), and one cell of one pair of frames in the distance matrix (a share of a GEMM's dot
/// product): the quick pipeline's calibration and spray on 2 cores (docs/performance.md, "Recurrence
/// set-up against tracer steps").
inline constexpr double kReadWorkPerCell = 0.3;
inline constexpr double kMatrixWorkPerCellPair = 3e-4;

/// The work of prepareRecurrence() on `databasePath` for `scene`; reads only the file's header.
RecurrenceWork recurrenceWork(const Scene& scene, const std::string& databasePath);

/// A calibration or spray job's progress as one fraction: the recurrence set-up, then the tracer
/// steps (summed over D0 values or ensemble members), each weighted by its expected work.
class TracerJobWork {
 public:
  TracerJobWork(const RecurrenceWork& recurrence, double tracerSteps)
      : recurrence_(recurrence.total()), tracerSteps_(tracerSteps) {}
  /// The whole job's fraction with `recurrenceDone` of the set-up (in [0, 1]) and `tracerStepsDone`.
  double fraction(double recurrenceDone, double tracerStepsDone) const {
    const double total = recurrence_ + tracerSteps_;
    return total > 0.0 ? std::min(1.0, (recurrenceDone * recurrence_ + tracerStepsDone) / total) : 1.0;
  }
  /// A sweep that grows by a D0 value has more tracer steps to do.
  void setTracerSteps(double tracerSteps) { tracerSteps_ = tracerSteps; }

 private:
  double recurrence_;
  double tracerSteps_;
};

/// Opens `databasePath`, gets its recurrence matrix and builds a path of at least `frames` entries.
/// `stopRequested` is polled (from several threads) between the frames read and the matrix's tiles:
/// true ends the setup with rcfd::Cancelled, leaving the database file as it was. `progress`, if given,
/// is called with the fraction of the setup's work done (recurrenceWork()), non-decreasing, from one
/// thread at a time, as frames are read and tiles computed.
RecurrenceSetup prepareRecurrence(const Scene& scene, const std::string& databasePath, std::int64_t frames,
                                  std::uint64_t seed, const std::function<bool()>& stopRequested = {},
                                  const std::function<void(double)>& progress = {});

/// The path of the scene's generator through `matrix`, of at least `frames` entries, for `seed`, and
/// its statistics: what prepareRecurrence builds for its seed (an ensemble's further members draw
/// theirs with it from the one matrix). InputError for an unknown generator.
RecurrencePath generateRecurrencePath(const Scene& scene, const RecurrenceMatrix& matrix, std::int64_t frames,
                                      std::uint64_t seed, PathStatistics* statistics = nullptr);

}  // namespace rcfd
