#include "jobs/RecurrenceSetup.hpp"

#include <spdlog/spdlog.h>

#include <limits>
#include <mutex>
#include <optional>

#include "core/Errors.hpp"
#include "geometry/Apparatus.hpp"
#include "jobs/Cancellation.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {

namespace {

/// The frame count and cell count of a database, and its stored matrix if it has one.
struct Probe {
  int frames = 0;
  std::int64_t cells = 0;
  bool hasMatrix = false;
  std::optional<RecurrenceMatrix> stored;  ///< read only when asked for
};

Probe probeDatabase(const std::string& databasePath, bool readMatrix) {
  // A cache as large as any database reads no frame on open: only the counts are needed here. The
  // probe is closed again at once: the matrix must be stored while no reader holds the file.
  Probe p;
  {
    auto probe = FieldDatabase::open(databasePath, FrameStorage{std::numeric_limits<std::int64_t>::max()});
    p.frames = probe->frameCount();
    p.cells = probe->grid().cellCount();
  }
  if (readMatrix) {
    p.stored = loadRecurrenceMatrix(databasePath, p.frames);
    p.hasMatrix = p.stored.has_value();
  } else {
    p.hasMatrix = hasStoredRecurrenceMatrix(databasePath, p.frames);
  }
  return p;
}

RecurrenceWork workOf(const Scene& scene, const Probe& p) {
  RecurrenceWork w;
  w.frames = p.frames;
  w.cells = p.cells;
  w.readIntoMemory = scene.rcfd.frame_cache_bytes == 0;
  w.matrixStored = p.hasMatrix;
  // A computed matrix is stored into the file with no reader holding it: the frames are read again.
  if (w.readIntoMemory) w.read = (w.matrixStored ? 1.0 : 2.0) * kReadWorkPerCell * double(p.frames) * double(p.cells);
  if (!w.matrixStored) w.matrix = kMatrixWorkPerCellPair * 0.5 * double(p.frames) * double(p.frames) * double(p.cells);
  return w;
}

}  // namespace

RecurrenceWork recurrenceWork(const Scene& scene, const std::string& databasePath) {
  return workOf(scene, probeDatabase(databasePath, false));
}

RecurrenceSetup prepareRecurrence(const Scene& scene, const std::string& databasePath, std::int64_t frames,
                                  std::uint64_t seed, const std::function<bool()>& stopRequested,
                                  const std::function<void(double)>& progress) {
  RecurrenceSetup setup;
  Probe probe = probeDatabase(databasePath, true);
  const RecurrenceWork work = workOf(scene, probe);
  if (probe.stored) {
    setup.matrix = std::move(*probe.stored);
    setup.matrixWasStored = true;
  }
  // The reading's share of the work, then the matrix's; reported from one thread at a time (the
  // matrix's tiles finish on several), never backwards.
  std::mutex reporting;
  double reported = 0.0;
  auto report = [&](double share, double offset, double f) {
    if (!progress || !(work.total() > 0.0) || !reporting.try_lock()) return;
    const double now = (offset + share * f) / work.total();
    if (now > reported) progress(reported = std::min(1.0, now));
    reporting.unlock();
  };
  FrameStorage storage{scene.rcfd.frame_cache_bytes, TracerEffectRegistry::needsVelocitySpread(scene.effects),
                       !TracerEffectRegistry::requiresVelocitySpread(scene.effects), stopRequested};
  const double readOnce = work.matrixStored ? work.read : 0.5 * work.read;
  storage.progress = [&](double f) { report(readOnce, 0.0, f); };
  setup.database = FieldDatabase::open(databasePath, storage);
  if (!setup.matrixWasStored) {
    RecurrenceOptions options;
    options.stopRequested = stopRequested;
    options.progress = [&](double f) { report(work.matrix, readOnce, f); };
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
    storage.progress = [&](double f) { report(readOnce, readOnce + work.matrix, f); };
    if (!setup.database) setup.database = FieldDatabase::open(databasePath, storage);
  }
  setup.frameSpacing = frameSpacing(*setup.database, SprayZone(scene.spray.spray_zone, Apparatus(scene.apparatus)));
  if (const std::string warning = sparseFramesWarning(setup.frameSpacing); !warning.empty()) spdlog::warn("{}", warning);
  if (!PathGeneratorRegistry::contains(scene.rcfd.path.type)) {
    throw InputError("scene", "/rcfd/path/type", PathGeneratorRegistry::unknownNameMessage(scene.rcfd.path.type));
  }
  if (stopRequested && stopRequested()) throw Cancelled("stopped before building the recurrence path");
  setup.path = generateRecurrencePath(scene, setup.matrix, frames, seed, &setup.pathStats);
  if (progress) progress(1.0);
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
