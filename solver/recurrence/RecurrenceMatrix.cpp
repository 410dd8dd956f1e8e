#include "recurrence/RecurrenceMatrix.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <random>
#include <type_traits>

#include "core/Errors.hpp"
#include "core/Hdf5.hpp"

namespace rcfd {

RecurrenceNorm parseRecurrenceNorm(const std::string& name, const std::string& pointer) {
  return parseNamedValue(kRecurrenceNorms, name, "recurrence", pointer);
}

std::string toString(RecurrenceNorm norm) { return nameOf(kRecurrenceNorms, norm); }

FieldComponent parseFieldComponent(const std::string& name, const std::string& pointer) {
  FieldComponent f;
  f.name = name;
  if (name == "alpha_p") return f;
  if (name.size() == 5 && (name.rfind("u_p.", 0) == 0 || name.rfind("u_g.", 0) == 0)) {
    const char axis = name[4];
    if (axis >= 'x' && axis <= 'z') {
      f.source = name[2] == 'p' ? FieldComponent::Source::UP : FieldComponent::Source::UG;
      f.component = axis - 'x';
      return f;
    }
  }
  throw InputError("recurrence", pointer,
                   "\"" + name + "\" is not a field; valid names are: alpha_p u_g.x u_g.y u_g.z u_p.x "
                                 "u_p.y u_p.z");
}

ScalarSeries scalarSeries(const FieldDatabase& db, const FieldComponent& field) {
  const auto& fluid = db.fluidFraction();
  const double volume = db.grid().cellVolume();
  auto cells = std::make_shared<std::vector<std::int64_t>>();
  ScalarSeries s;
  s.frames = db.frameCount();
  for (std::size_t c = 0; c < fluid.size(); ++c) {
    if (fluid[c] > 0.0f) {
      cells->push_back(std::int64_t(c));
      s.weights.push_back(double(fluid[c]) * volume);  // V_open,c [m3]
    }
  }
  const FieldDatabase* source = &db;
  s.fetch = [source, cells, field](int frame, float* out) {
    const auto f = source->frame(frame);
    for (std::size_t k = 0; k < cells->size(); ++k) out[k] = field.value(*f, (*cells)[k]);
  };
  return s;
}

namespace {

/// A stop request seen from inside parallel loops: the first true answer is kept, every later poll
/// skips its work at once, and the caller throws after the loop (exceptions must not leave an OpenMP
/// region). Also counts the work done, in units of one frame loaded, for the progress.
class StopPoll {
 public:
  explicit StopPoll(const std::function<bool()>& request, const std::function<void(double)>& progress = kNone,
                    double totalWork = 0.0)
      : request_(request), progress_(progress), total_(totalWork) {}
  bool operator()() const {
    if (stopped_.load(std::memory_order_relaxed)) return true;
    if (!request_ || !request_()) return false;
    stopped_.store(true, std::memory_order_relaxed);
    return true;
  }
  void throwIfStopped() const {
    if (stopped_.load()) throw Cancelled("stopped while computing the recurrence matrix; nothing of it is kept");
  }
  /// `units` of work done (from any thread).
  void advance(double units) const {
    if (!progress_ || !(total_ > 0.0)) return;
    const double done = done_.fetch_add(units, std::memory_order_relaxed) + units;
    progress_(std::min(1.0, done / total_));
  }

 private:
  static inline const std::function<void(double)> kNone{};
  const std::function<bool()>& request_;
  const std::function<void(double)>& progress_;
  double total_;
  mutable std::atomic<bool> stopped_{false};
  mutable std::atomic<double> done_{0.0};
};

/// Work of one entry of a tile product against one frame loaded: a frame load copies and transforms
/// every cell's value, an entry is a dot product over the cells inside a GEMM or a vectorised loop,
/// about ten times faster per value.
constexpr double kEntryWork = 0.1;

struct Tile {
  int first, count;
};

std::vector<Tile> tiles(int first, int count, int size) {
  std::vector<Tile> out;
  for (int t = 0; t < count; t += size) out.push_back({first + t, std::min(size, count - t)});
  return out;
}

// Fetches frames [first, first + count) into columns, transformed by `store(column, values)`. A frame
// that fails to load (e.g. NaN found by a cached database) throws after the parallel loop: exceptions
// must not leave an OpenMP region.
template <class Store>
void loadFrames(const ScalarSeries& s, int first, int count, Store store, const StopPoll& stop) {
  const std::size_t cells = s.weights.size();
  std::exception_ptr failure;
  // Small loads stay on one thread: an OpenMP region costs more than it saves when cores are shared.
#pragma omp parallel if (std::int64_t(count) * std::int64_t(cells) > (1 << 18))
  {
    std::vector<float> buffer(cells);
#pragma omp for schedule(dynamic, 1)
    for (int f = 0; f < count; ++f) {
      if (stop()) continue;
      try {
        s.fetch(first + f, buffer.data());
        store(f, buffer);
        stop.advance(1.0);
      } catch (...) {
#pragma omp critical(rcfd_recurrence_failure)
        if (!failure) failure = std::current_exception();
      }
    }
  }
  if (failure) std::rethrow_exception(failure);
  stop.throwIfStopped();
}

// The tile pairs (a, b) of a block pair, row by row; on a diagonal block (rows and columns the same
// frames) only b >= a, since D is symmetric. The work estimate of distanceMatrix() goes through them in
// the same order.
std::vector<std::pair<int, int>> tilePairs(std::size_t rowTiles, std::size_t columnTiles, bool diagonalBlock) {
  std::vector<std::pair<int, int>> pairs;
  for (int a = 0; a < int(rowTiles); ++a)
    for (int b = diagonalBlock ? a : 0; b < int(columnTiles); ++b) pairs.emplace_back(a, b);
  return pairs;
}

// The blocked loop over pairs of frames that both distance forms share. The frames are split into
// blocks of `framesPerBlock` for memory: for every block pair on or above the diagonal the rows' block
// X and the columns' block Y are resident, each filled by `load(first, count, matrix)` with one column
// per frame. Each block pair is split into tiles of `tileFrames` frames, and
// `tilePair(X, Y, a, b, rowFrame, columnFrame)` computes the entries of tile a of X against tile b of
// Y, whose first columns are frames rowFrame and columnFrame; tiles below the diagonal are skipped.
// Tiles are independent and run in parallel, each on one thread (Eigen never splits a product itself:
// EIGEN_DONT_PARALLELIZE, so the sums do not depend on the thread count), which keeps both cores busy
// even when other processes share them. A
// stop request is polled before every tile and thrown after the parallel loop (StopPoll).
template <class Matrix, class Load, class TilePair>
void forEachTilePair(int frames, int framesPerBlock, int tileFrames, Eigen::Index cells, Load&& load,
                     TilePair&& tilePair, const StopPoll& stop) {
  const auto blocks = tiles(0, frames, framesPerBlock);
  Matrix XP, XQ;
  for (std::size_t p = 0; p < blocks.size(); ++p) {
    load(blocks[p].first, blocks[p].count, XP);
    for (std::size_t q = p; q < blocks.size(); ++q) {
      if (q != p) load(blocks[q].first, blocks[q].count, XQ);
      const Matrix& Y = q == p ? XP : XQ;
      const auto tp = tiles(0, blocks[p].count, tileFrames);
      const auto tq = tiles(0, blocks[q].count, tileFrames);
      const auto pairs = tilePairs(tp.size(), tq.size(), q == p);
#pragma omp parallel for schedule(dynamic, 1) if (pairs.size() > 1 && double(blocks[p].count) * blocks[q].count * cells > 1e7)
      for (int k = 0; k < int(pairs.size()); ++k) {
        if (stop()) continue;
        const Tile a = tp[std::size_t(pairs[std::size_t(k)].first)];
        const Tile b = tq[std::size_t(pairs[std::size_t(k)].second)];
        tilePair(XP, Y, a, b, blocks[p].first, blocks[q].first);
        stop.advance(kEntryWork * a.count * b.count);
      }
      stop.throwIfStopped();
    }
  }
}

// Gram form of the L2 distances. Frames are centred on frame 0 (D is unchanged, (a_i - r) - (a_j - r)
// = a_i - a_j) so n_i + n_j - 2 G_ij cancels less, then scaled by sqrt(V_c): G_ij = sum_c V_c x_i x_j.
// Scalar = double: one double GEMM per tile pair. Scalar = float: float GEMMs over chunks of
// `floatChunk` cells, each chunk's partial sums added in double, so rounding grows with the chunk, not
// with the cell count (docs/performance.md compares both).
template <class Scalar>
Eigen::MatrixXd l2Distances(const ScalarSeries& s, int framesPerBlock, int tileFrames, std::int64_t* clamped,
                            const StopPoll& stop) {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  constexpr Eigen::Index floatChunk = 512;
  const int n = s.frames;
  const Eigen::Index cells = Eigen::Index(s.weights.size());
  std::vector<float> reference(s.weights.size());
  s.fetch(0, reference.data());
  Eigen::VectorXd sqrtW(cells);
  for (Eigen::Index c = 0; c < cells; ++c) sqrtW[c] = std::sqrt(s.weights[std::size_t(c)]);

  Eigen::VectorXd norms(n);
  auto load = [&](int first, int count, Matrix& X) {
    X.resize(cells, count);
    loadFrames(s, first, count, [&](int f, const std::vector<float>& v) {
      Scalar* col = X.col(f).data();
      double squared = 0.0;
      for (Eigen::Index c = 0; c < cells; ++c) {
        const double x = sqrtW[c] * (double(v[std::size_t(c)]) - reference[std::size_t(c)]);
        col[c] = Scalar(x);
        squared += double(col[c]) * double(col[c]);  // n_i in double from the stored values
      }
      norms[first + f] = squared;
    }, stop);
  };

  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, n);  // upper triangle filled
  // G over one tile pair: one GEMM in double, or float GEMMs per chunk of cells summed in double.
  auto gramTile = [&](const Matrix& X, const Matrix& Y, Tile a, Tile b, int rowFrame, int columnFrame) {
    auto target = G.block(rowFrame + a.first, columnFrame + b.first, a.count, b.count);
    if constexpr (std::is_same_v<Scalar, double>) {
      target.noalias() = X.middleCols(a.first, a.count).transpose() * Y.middleCols(b.first, b.count);
    } else {
      Eigen::MatrixXf partial(a.count, b.count);
      // Polled per chunk too: one tile over 10^6 cells takes seconds.
      for (Eigen::Index c0 = 0; c0 < cells && !stop(); c0 += floatChunk) {
        const Eigen::Index len = std::min(floatChunk, cells - c0);
        partial.noalias() = X.block(c0, a.first, len, a.count).transpose() * Y.block(c0, b.first, len, b.count);
        target += partial.cast<double>();
      }
    }
  };
  forEachTilePair<Matrix>(n, framesPerBlock, tileFrames, cells, load, gramTile, stop);
  std::int64_t negatives = 0;
  Eigen::MatrixXd& D = G;  // converted in place, upper triangle first
#pragma omp parallel for schedule(dynamic, 16) reduction(+ : negatives) if (n > 512)
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      double d = norms[i] + norms[j] - 2.0 * D(i, j);
      // Round-off can leave a tiny negative value for two nearly equal frames: it is a zero distance.
      if (d < 0.0) {
        d = 0.0;
        ++negatives;
      }
      D(i, j) = d;
    }
  }
  for (int i = 0; i < n; ++i) {
    D(i, i) = 0.0;
    for (int j = i + 1; j < n; ++j) D(j, i) = D(i, j);
  }
  if (clamped) *clamped = negatives;
  return G;
}

// L1 (volume-weighted sum of |a_i - a_j|) and max (largest |a_i - a_j|) by a direct loop, blocked over
// frames (memory) and cells (cache).
Eigen::MatrixXd directDistances(const ScalarSeries& s, RecurrenceNorm norm, int framesPerBlock, int tileFrames,
                                const StopPoll& stop) {
  const int n = s.frames;
  const Eigen::Index cells = Eigen::Index(s.weights.size());
  const double* w = s.weights.data();
  constexpr Eigen::Index cellChunk = 1024;
  using MatrixXfC = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>;
  auto load = [&](int first, int count, MatrixXfC& X) {
    X.resize(cells, count);
    loadFrames(s, first, count, [&](int f, const std::vector<float>& v) {
      std::copy(v.begin(), v.end(), X.col(f).data());
    }, stop);
  };
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  const bool isMax = norm == RecurrenceNorm::Max;
  // One tile pair's entries above the diagonal, accumulated chunk by chunk of cells (the cache
  // blocking), then written to both triangles.
  auto distanceTile = [&](const MatrixXfC& X, const MatrixXfC& Y, Tile a, Tile b, int rowFrame, int columnFrame) {
    Eigen::MatrixXd acc = Eigen::MatrixXd::Zero(a.count, b.count);
    for (Eigen::Index c0 = 0; c0 < cells; c0 += cellChunk) {
      const Eigen::Index len = std::min(cellChunk, cells - c0);
      for (int i = 0; i < a.count; ++i) {
        const float* xi = X.col(a.first + i).data() + c0;
        const int gi = rowFrame + a.first + i;
        for (int j = 0; j < b.count; ++j) {
          const int gj = columnFrame + b.first + j;
          if (gj <= gi) continue;
          const float* xj = Y.col(b.first + j).data() + c0;
          if (isMax) {
            float m = 0.0f;
#pragma omp simd reduction(max : m)
            for (Eigen::Index c = 0; c < len; ++c) m = std::max(m, std::fabs(xi[c] - xj[c]));
            acc(i, j) = std::max(acc(i, j), double(m));
          } else {
            double sum = 0.0;
#pragma omp simd reduction(+ : sum)
            for (Eigen::Index c = 0; c < len; ++c)
              sum += w[c0 + c] * std::fabs(double(xi[c]) - double(xj[c]));
            acc(i, j) += sum;
          }
        }
      }
    }
    for (int i = 0; i < a.count; ++i)
      for (int j = 0; j < b.count; ++j) {
        const int gi = rowFrame + a.first + i, gj = columnFrame + b.first + j;
        if (gj > gi) D(gi, gj) = D(gj, gi) = acc(i, j);
      }
  };
  forEachTilePair<MatrixXfC>(n, framesPerBlock, tileFrames, cells, load, distanceTile, stop);
  return D;
}

}  // namespace

Eigen::MatrixXd distanceMatrix(const ScalarSeries& series, RecurrenceNorm norm,
                               std::int64_t memoryBudgetBytes, int tileFrames, int* blocks,
                               std::int64_t* clamped, GramPrecision precision,
                               const std::function<bool()>& stopRequested,
                               const std::function<void(double)>& progress) {
  const int n = series.frames;
  if (n < 1 || series.weights.empty()) {
    throw InputError("recurrence", "/frames", "no frames or no open cells to compare");
  }
  tileFrames = std::max(1, tileFrames);
  const std::int64_t bytesPerFrame =
      std::int64_t(series.weights.size()) * (norm == RecurrenceNorm::L2 && precision != GramPrecision::FloatChunked ? 8 : 4);
  // All frames in one block if they fit the budget; otherwise two blocks are resident at a time (rows
  // P and columns Q of a block pair), each half the budget.
  const std::int64_t perBlock = bytesPerFrame * n <= memoryBudgetBytes
                                    ? n
                                    : std::max<std::int64_t>(1, memoryBudgetBytes / (2 * bytesPerFrame));
  const int framesPerBlock = int(std::min<std::int64_t>(n, perBlock));
  if (blocks) *blocks = (n + framesPerBlock - 1) / framesPerBlock;
  if (clamped) *clamped = 0;
  // The work the loops below do, in frames loaded (StopPoll::advance), for the progress.
  double work = 0.0;
  {
    const auto b = tiles(0, n, framesPerBlock);
    for (std::size_t p = 0; p < b.size(); ++p) {
      work += b[p].count;
      for (std::size_t q = p; q < b.size(); ++q) {
        if (q != p) work += b[q].count;
        const auto tp = tiles(0, b[p].count, tileFrames), tq = tiles(0, b[q].count, tileFrames);
        for (const auto& [i, j] : tilePairs(tp.size(), tq.size(), q == p))
          work += kEntryWork * tp[std::size_t(i)].count * tq[std::size_t(j)].count;
      }
    }
  }
  const StopPoll stop(stopRequested, progress, work);
  if (norm == RecurrenceNorm::L2) {
    return precision == GramPrecision::FloatChunked
               ? l2Distances<float>(series, framesPerBlock, tileFrames, clamped, stop)
               : l2Distances<double>(series, framesPerBlock, tileFrames, clamped, stop);
  }
  return directDistances(series, norm, framesPerBlock, tileFrames, stop);
}

RecurrenceMatrix normaliseDistances(const Eigen::MatrixXd& D) {
  RecurrenceMatrix m;
  const double maxD = D.size() ? D.maxCoeff() : 0.0;
  m.normalisation = maxD;
  if (maxD > 0.0) {
    m.R = (1.0 - D.array() / maxD).matrix().cast<float>();  // Eq. (6) with N_alphaG of Eq. (7)
  } else {
    m.R = Eigen::MatrixXf::Ones(D.rows(), D.cols());  // every frame equal: all states recur
  }
  m.R.diagonal().setOnes();
  return m;
}

namespace {

// Largest |R(i, j) - R_exact(i, j)| over `pairs` seeded random entries and the most distant pair, with
// R_exact from Eq. (6) summed in double straight from the frames (normalised by m's max D).
double spotCheck(const ScalarSeries& s, const RecurrenceMatrix& m, int pairs,
                 const std::function<bool()>& stopRequested) {
  const int n = s.frames;
  std::vector<std::pair<int, int>> entries;
  Eigen::Index fi = 0, fj = 0;
  m.R.minCoeff(&fi, &fj);
  entries.emplace_back(int(fi), int(fj));
  std::mt19937_64 rng(20240521);
  for (int k = 0; k < pairs; ++k)
    entries.emplace_back(int(rng() % std::uint64_t(n)), int(rng() % std::uint64_t(n)));
  const std::size_t cells = s.weights.size();
  double worst = 0.0;
  std::vector<float> a(cells), b(cells);
  const StopPoll stop(stopRequested);
  for (const auto& [i, j] : entries) {
    if (stop()) stop.throwIfStopped();
    s.fetch(i, a.data());
    s.fetch(j, b.data());
    double d = 0.0;
    for (std::size_t c = 0; c < cells; ++c) {
      const double diff = double(a[c]) - double(b[c]);
      d += s.weights[c] * diff * diff;  // Eq. (6)
    }
    const double exact = m.normalisation > 0.0 ? 1.0 - d / m.normalisation : 1.0;
    worst = std::max(worst, std::abs(exact - double(m.R(i, j))));
  }
  return worst;
}

RecurrenceMatrix computeOnce(const ScalarSeries& series, const RecurrenceOptions& options, GramPrecision gram) {
  int blocks = 1;
  std::int64_t clamped = 0;
  const Eigen::MatrixXd D = distanceMatrix(series, options.norm, options.memoryBudgetBytes, options.tileFrames,
                                           &blocks, &clamped, gram, options.stopRequested, options.progress);
  RecurrenceMatrix m = normaliseDistances(D);
  m.norm = options.norm;
  m.field = options.field;
  m.frameBlocks = blocks;
  m.clampedNegatives = clamped;
  m.gramUsed = gram;
  return m;
}

}  // namespace

RecurrenceMatrix computeRecurrenceMatrix(const ScalarSeries& series, const RecurrenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  RecurrenceMatrix m;
  if (options.norm != RecurrenceNorm::L2 || options.gram != GramPrecision::Auto) {
    m = computeOnce(series, options, options.gram == GramPrecision::Auto ? GramPrecision::Double : options.gram);
  } else {
    m = computeOnce(series, options, GramPrecision::FloatChunked);
    m.spotCheckError = spotCheck(series, m, options.autoCheckPairs, options.stopRequested);
    if (!(m.spotCheckError <= options.autoTolerance)) {
      const double failedError = m.spotCheckError;
      m = computeOnce(series, options, GramPrecision::Double);
      m.spotCheckError = failedError;
      m.autoFellBack = true;
    }
  }
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return m;
}

RecurrenceMatrix computeRecurrenceMatrix(const FieldDatabase& db, const RecurrenceOptions& options) {
  const FieldComponent field = parseFieldComponent(options.field);
  return computeRecurrenceMatrix(scalarSeries(db, field), options);
}

void storeRecurrenceMatrix(const std::string& databasePath, const RecurrenceMatrix& matrix) {
  using h5::Handle;
  h5::silenceErrors();
  Handle file(H5Fopen(databasePath.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
  if (!file.valid()) {
    throw RunError(databasePath + ": cannot open for writing /recurrence/matrix (read-only, or open "
                                  "elsewhere)");
  }
  if (!h5::linkExists(file, "/recurrence")) {
    Handle g = h5::check(H5Gcreate2(file, "/recurrence", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                         databasePath + ": creating /recurrence");
  }
  const hsize_t dims[2] = {hsize_t(matrix.R.rows()), hsize_t(matrix.R.cols())};
  Handle set;
  if (h5::linkExists(file, layout::recurrenceMatrix)) {
    set = Handle(H5Dopen2(file, layout::recurrenceMatrix, H5P_DEFAULT));
    const auto old = set.valid() ? h5::datasetDims(set) : std::vector<hsize_t>{};
    if (old != std::vector<hsize_t>{dims[0], dims[1]}) {
      set.reset();
      H5Ldelete(file, layout::recurrenceMatrix, H5P_DEFAULT);
    }
  }
  if (!set.valid()) {
    Handle space = h5::check(H5Screate_simple(2, dims, nullptr), "/recurrence/matrix");
    set = h5::check(H5Dcreate2(file, layout::recurrenceMatrix, H5T_IEEE_F32LE, space, H5P_DEFAULT,
                               H5P_DEFAULT, H5P_DEFAULT),
                    databasePath + ": creating /recurrence/matrix");
  }
  // R is symmetric, so Eigen's column-major storage is also the row-major [N][N] layout.
  h5::checkStatus(H5Dwrite(set, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, matrix.R.data()),
                  databasePath + ": writing /recurrence/matrix");
  h5::writeStringAttribute(set, "norm", toString(matrix.norm));
  h5::writeStringAttribute(set, "field", matrix.field);
  h5::writeDoubleAttribute(set, "normalisation", {matrix.normalisation});
  set.reset();
  if (H5Fclose(file.release()) < 0) throw RunError(databasePath + ": closing after writing the matrix failed");
}

namespace {
/// The stored matrix's dataset if it is one of `expectedFrames` squared floats (an invalid handle
/// otherwise); `file` receives the open file.
h5::Handle storedMatrixSet(const std::string& databasePath, int expectedFrames, h5::Handle& file) {
  using h5::Handle;
  h5::silenceErrors();
  file = Handle(h5::openReadOnlyWaitingForWriter(databasePath));
  if (!file.valid() || !h5::linkExists(file, layout::recurrenceMatrix)) return Handle();
  Handle set(H5Dopen2(file, layout::recurrenceMatrix, H5P_DEFAULT));
  if (!set.valid() || h5::datasetClass(set) != H5T_FLOAT) return Handle();
  if (h5::datasetDims(set) != std::vector<hsize_t>{hsize_t(expectedFrames), hsize_t(expectedFrames)})
    return Handle();
  return set;
}
}  // namespace

bool hasStoredRecurrenceMatrix(const std::string& databasePath, int expectedFrames) {
  h5::Handle file;
  return storedMatrixSet(databasePath, expectedFrames, file).valid();
}

std::optional<RecurrenceMatrix> loadRecurrenceMatrix(const std::string& databasePath, int expectedFrames) {
  h5::Handle file;
  const h5::Handle set = storedMatrixSet(databasePath, expectedFrames, file);
  if (!set.valid()) return std::nullopt;
  RecurrenceMatrix m;
  Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> R(expectedFrames, expectedFrames);
  if (H5Dread(set, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, R.data()) < 0) return std::nullopt;
  m.R = R;
  if (auto n = h5::readStringAttribute(set, "norm")) m.norm = parseRecurrenceNorm(*n, "/recurrence/matrix@norm");
  if (auto f = h5::readStringAttribute(set, "field")) m.field = *f;
  if (auto v = h5::readNumericAttribute(set, "normalisation"); v && v->size() == 1) m.normalisation = (*v)[0];
  return m;
}

RecurrenceSummary summariseRecurrence(const Eigen::MatrixXf& R, int maxLags) {
  RecurrenceSummary s;
  const Eigen::Index n = R.rows();
  s.diagonalMeans.assign(std::size_t(n), 0.0);
  double offSum = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    double sum = 0.0;
    for (Eigen::Index i = 0; i + k < n; ++i) sum += R(i, i + k);
    s.diagonalMeans[std::size_t(k)] = sum / double(n - k);
    if (k > 0) offSum += 2.0 * sum;
  }
  s.meanOffDiagonal = n > 1 ? offSum / double(n * n - n) : 0.0;
  const auto& m = s.diagonalMeans;
  for (Eigen::Index k = 2; k <= n / 2 && k + 1 < n; ++k) {
    if (m[std::size_t(k)] > m[std::size_t(k - 1)] && m[std::size_t(k)] >= m[std::size_t(k + 1)]) {
      s.strongestLags.push_back({int(k), m[std::size_t(k)]});
    }
  }
  std::stable_sort(s.strongestLags.begin(), s.strongestLags.end(),
                   [](const RecurrenceLag& a, const RecurrenceLag& b) { return a.meanR > b.meanR; });
  if (int(s.strongestLags.size()) > maxLags) s.strongestLags.resize(std::size_t(maxLags));
  return s;
}

}  // namespace rcfd
