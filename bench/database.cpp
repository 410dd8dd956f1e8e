// rcfd-bench database: writing and loading a field database of the paper's size, 2000 frames x 73,647
// cells x 7 float32 (4.12 GB; --quick: 200 frames), plus the recurrence matrix from the loaded
// database (the paper: 12 min on 12 cores for loading 16 GB and the matrix). Loads are measured cold
// (the file's pages dropped from the page cache with posix_fadvise after fsync) and warm. Deflate
// (shuffle + deflate level 1) is compared on the first 200 frames. The file goes to $RCFD_BENCH_DIR
// (default /tmp) and is removed afterwards.

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "BenchRegistry.hpp"
#include "SyntheticFields.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "recurrence/RecurrenceMatrix.hpp"

namespace rcfd::bench {
namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Writes `frames` synthetic frames; returns the seconds spent in append() (frame generation excluded).
double writeDatabase(const std::string& path, const CartesianGrid& grid, int frames, FieldDatabaseWriterOptions options) {
  FieldDatabaseWriter writer(path, grid, paperSizeFluid(grid), 0.005, "{\"name\": \"synthetic paper-size\"}", options);
  FieldFrame f = makeFrame(grid);
  double seconds = 0.0;
  for (int n = 0; n < frames; ++n) {
    syntheticFrame(grid, n, f);
    const auto t0 = std::chrono::steady_clock::now();
    writer.append(f);
    seconds += since(t0);
  }
  const auto t0 = std::chrono::steady_clock::now();
  writer.close();
  return seconds + since(t0);
}

// Flushes the file to disk and drops its pages from the page cache, so the next read comes from disk.
void dropFromPageCache(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
  ::close(fd);
}

double loadSeconds(const std::string& path, bool cold) {
  if (cold) dropFromPageCache(path);
  const auto t0 = std::chrono::steady_clock::now();
  auto db = FieldDatabase::open(path);
  return since(t0);
}

nlohmann::json run(const Options& options) {
  const int frames = options.quick ? 200 : 2000;
  const CartesianGrid grid = paperSizeGrid();
  const char* dirEnv = std::getenv("RCFD_BENCH_DIR");
  const std::string dir = dirEnv ? dirEnv : "/tmp";
  const std::string path = dir + "/rcfd-bench-database-" + std::to_string(::getpid()) + ".h5";
  const double frameMb = double(grid.cellCount()) * 7 * 4 / 1e6;
  const double dataMb = frameMb * frames;
  std::cout << "database: " << frames << " frames x " << grid.cellCount() << " cells x 7 float32 = " << dataMb
            << " MB -> " << path << "\n";

  const double writeS = writeDatabase(path, grid, frames, {});
  const auto fileBytes = std::filesystem::file_size(path);
  std::cout << "  write (append + flush per frame): " << writeS << " s, " << dataMb / writeS << " MB/s; file "
            << double(fileBytes) / 1e9 << " GB (" << double(fileBytes) / (dataMb * 1e6) << " x raw)\n";
  const double coldS = loadSeconds(path, true);
  std::cout << "  load all frames into RAM, cold: " << coldS << " s, " << dataMb / coldS << " MB/s\n";
  const double warmS = loadSeconds(path, false);
  std::cout << "  load all frames into RAM, warm page cache: " << warmS << " s, " << dataMb / warmS << " MB/s\n";

  // Streaming through a 256 MB LRU cache (the mode for databases larger than RAM), cold.
  dropFromPageCache(path);
  auto t0 = std::chrono::steady_clock::now();
  double matrixFromDbS = 0.0;
  std::int64_t misses = 0;
  {
    auto db = FieldDatabase::open(path, FrameStorage{std::int64_t(256) << 20});
    for (int n = 0; n < frames; ++n) db->frame(n);
    misses = db->cacheStats().misses;
  }
  const double streamS = since(t0);
  std::cout << "  sequential read through a 256 MB frame cache, cold: " << streamS << " s, " << dataMb / streamS
            << " MB/s (" << misses << " misses)\n";

  // Load + matrix, as the paper's 12 minutes measured.
  dropFromPageCache(path);
  t0 = std::chrono::steady_clock::now();
  {
    auto db = FieldDatabase::open(path);
    const RecurrenceMatrix m = computeRecurrenceMatrix(*db);
    matrixFromDbS = m.seconds;
  }
  const double loadAndMatrixS = since(t0);
  std::cout << "  cold load + recurrence matrix: " << loadAndMatrixS << " s (matrix " << matrixFromDbS << " s)\n";
  std::filesystem::remove(path);

  // Compression on (at most) 200 frames.
  const int small = std::min(frames, 200);
  const double smallMb = frameMb * small;
  nlohmann::json compression = nlohmann::json::array();
  for (auto [level, shuffle] : {std::pair{0, false}, std::pair{1, true}, std::pair{1, false}}) {
    const double w = writeDatabase(path, grid, small, FieldDatabaseWriterOptions{level, shuffle});
    const double size = double(std::filesystem::file_size(path));
    const double load = loadSeconds(path, true);
    std::cout << "  " << small << " frames, deflate " << level << (shuffle ? " + shuffle" : "") << ": write "
              << smallMb / w << " MB/s, cold load " << smallMb / load << " MB/s, size " << size / (smallMb * 1e6)
              << " x raw\n";
    compression.push_back({{"deflate", level}, {"shuffle", shuffle}, {"write_mb_per_s", smallMb / w},
                           {"cold_load_mb_per_s", smallMb / load}, {"size_ratio", size / (smallMb * 1e6)}});
    std::filesystem::remove(path);
  }

  return {{"frames", frames},
          {"cells", grid.cellCount()},
          {"data_mb", dataMb},
          {"file_bytes", fileBytes},
          {"write_mb_per_s", dataMb / writeS},
          {"cold_load_mb_per_s", dataMb / coldS},
          {"warm_load_mb_per_s", dataMb / warmS},
          {"cache_stream_mb_per_s", dataMb / streamS},
          {"cold_load_and_matrix_seconds", loadAndMatrixS},
          {"matrix_seconds", matrixFromDbS},
          {"compression", compression}};
}

const bool registered = addBenchmark("database", "write/load speed and size of a paper-size field database", run);

}  // namespace
}  // namespace rcfd::bench
