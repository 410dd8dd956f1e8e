#include "jobs/RecurrenceSetup.hpp"

#include <spdlog/spdlog.h>

#include <limits>

#include "core/Errors.hpp"
#include "jobs/Cancellation.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {

RecurrenceSetup prepareRecurrence(const Scene& scene, const std::string& databasePath, std::int64_t frames,
                                  std::uint64_t seed, const std::function<bool()>& stopRequested) {
  RecurrenceSetup setup;
  {
    // Peek at the frame count first: the matrix must be stored while no reader holds the file.
    // A cache as large as any database reads no frame on open: only the frame count is needed here.
    auto probe = FieldDatabase::open(databasePath, FrameStorage{std::numeric_limits<std::int64_t>::max()});
    const int n = probe->frameCount();
    probe.reset();
    if (auto stored = loadRecurrenceMatrix(databasePath, n)) {
      setup.matrix = std::move(*stored);
      setup.matrixWasStored = true;
    }
  }
  const FrameStorage storage{scene.rcfd.frame_cache_bytes, TracerEffectRegistry::needsVelocitySpread(scene.effects),
                             !TracerEffectRegistry::requiresVelocitySpread(scene.effects), stopRequested};
  setup.database = FieldDatabase::open(databasePath, storage);
  if (!setup.matrixWasStored) {
    RecurrenceOptions options;
    options.stopRequested = stopRequested;
    setup.matrix = computeRecurrenceMatrix(*setup.database, options);
    spdlog::info("recurrence matrix of {} frames computed in {:.2f} s", setup.database->frameCount(),
                 setup.matrix.seconds);
    try {
      auto reopen = setup.database;
      setup.database.reset();
      reopen.reset();
      // Written into the database in place: a forced exit must not cut it (jobs/Cancellation.hpp).
      const ForcedExitDeferral keepTheDatabaseReadable;
      storeRecurrenceMatrix(databasePath, setup.matrix);
    } catch (const std::exception& e) {
      spdlog::warn("could not store the recurrence matrix in {}: {}", databasePath, e.what());
    }
    if (!setup.database) setup.database = FieldDatabase::open(databasePath, storage);
  }
  if (!PathGeneratorRegistry::contains(scene.rcfd.path.type)) {
    throw InputError("scene", "/rcfd/path/type", PathGeneratorRegistry::unknownNameMessage(scene.rcfd.path.type));
  }
  if (stopRequested && stopRequested()) throw Cancelled("stopped before building the recurrence path");
  setup.path = generateRecurrencePath(scene, setup.matrix, frames, seed, &setup.pathStats);
  return setup;
}

RecurrencePath generateRecurrencePath(const Scene& scene, const RecurrenceMatrix& matrix, std::int64_t frames,
                                      std::uint64_t seed, PathStatistics* statistics) {
  if (!PathGeneratorRegistry::contains(scene.rcfd.path.type)) {
    throw InputError("scene", "/rcfd/path/type", PathGeneratorRegistry::unknownNameMessage(scene.rcfd.path.type));
  }
  auto generator = PathGeneratorRegistry::create(scene.rcfd.path.type, scene.rcfd.path);
  RecurrencePath path = generator->generate(matrix.R, frames, seed);
  if (statistics) *statistics = pathStatistics(path, matrix.R);
  return path;
}

}  // namespace rcfd
