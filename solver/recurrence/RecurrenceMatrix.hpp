#pragma once
/// \file RecurrenceMatrix.hpp
/// The continuous recurrence plot of Eq. (6)-(7):
///   R(i, j) = 1 - D(i, j) / max D,  D(i, j) = sum_c V_c (a_i,c - a_j,c)^2
/// with V_c the open volume of cell c (fluid fraction x cell volume) and a the compared field
/// (alpha_P by default: the paper's alpha_G = 1 - alpha_P gives the same differences). The L2 norm is
/// computed through the Gram matrix, D = n_i + n_j - 2 G_ij with G = X^T W X, accumulated in double
/// (GramPrecision),
/// blocked over frames so only a memory budget's worth of frames is converted at a time. The L1 norm
/// (sum_c V_c |a_i - a_j|) and the max norm (max_c |a_i - a_j| over open cells) follow
/// CFDEMcoupling-PFM's absDiffNorm and maxNorm; they have no Gram form and use a blocked direct loop.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/Registry.hpp"
#include "fields/FieldDatabase.hpp"

namespace rcfd {

enum class RecurrenceNorm { L2, L1, Max };

/// The norms by name: `rcfd-solve recurrence --norm` and the stored matrix's `norm` attribute.
inline constexpr std::array<NamedValue<RecurrenceNorm>, 3> kRecurrenceNorms{{
    {"l2", RecurrenceNorm::L2, "Eq. (6): sum_c V_c (a_i - a_j)^2, through the Gram matrix"},
    {"l1", RecurrenceNorm::L1, "sum_c V_c |a_i - a_j| (CFDEMcoupling-PFM's absDiffNorm)"},
    {"max", RecurrenceNorm::Max, "max_c |a_i - a_j| over the open cells (CFDEMcoupling-PFM's maxNorm)"},
}};

/// The norm called `name`; rcfd::InputError naming `pointer` and the valid names otherwise.
RecurrenceNorm parseRecurrenceNorm(const std::string& name, const std::string& pointer = "--norm");
std::string toString(RecurrenceNorm norm);

/// A scalar per cell taken from a frame: alpha_p, or one component of u_p or u_g ("u_p.y").
struct FieldComponent {
  enum class Source { AlphaP, UP, UG };
  Source source = Source::AlphaP;
  int component = 0;  ///< 0, 1, 2 for x, y, z (velocities)
  std::string name = "alpha_p";

  float value(const FieldFrame& frame, std::int64_t cell) const {
    switch (source) {
      case Source::AlphaP: return frame.alpha_p[std::size_t(cell)];
      case Source::UP: return frame.u_p[std::size_t(3 * cell + component)];
      case Source::UG: return frame.u_g[std::size_t(3 * cell + component)];
    }
    return 0.0f;
  }
};

/// "alpha_p", "u_p.x|y|z", "u_g.x|y|z"; rcfd::InputError naming `pointer` otherwise.
FieldComponent parseFieldComponent(const std::string& name, const std::string& pointer = "--field");

/// The frames as seen by the matrix: `frames` snapshots of weights.size() values each.
struct ScalarSeries {
  int frames = 0;
  std::vector<double> weights;  ///< V_c per compared cell [m3]
  /// Writes the weights.size() values of frame `frame` to `out`; called from several threads.
  std::function<void(int frame, float* out)> fetch;
};

/// The open cells (fluid fraction > 0) of a database and the chosen field on them.
ScalarSeries scalarSeries(const FieldDatabase& db, const FieldComponent& field);

/// Arithmetic of the L2 Gram matrix. Double: double GEMM (R within ~3e-8 of a naive double loop).
/// FloatChunked: float GEMMs over chunks of 512 cells, the chunks summed in double (about twice as
/// fast; R within ~3e-7 at the paper's size). Auto (default): FloatChunked, then a spot check of
/// autoCheckPairs entries (and the most distant pair) against exact double sums; if any differs by
/// more than autoTolerance the matrix is recomputed in Double. docs/recurrence.md has the figures.
enum class GramPrecision { Double, FloatChunked, Auto };

struct RecurrenceOptions {
  RecurrenceNorm norm = RecurrenceNorm::L2;
  std::string field = "alpha_p";
  /// Frames converted to double at a time are limited to this many bytes (two blocks resident).
  std::int64_t memoryBudgetBytes = std::int64_t(1536) << 20;
  int tileFrames = 128;  ///< frames per tile of the parallel loop over tile pairs
  GramPrecision gram = GramPrecision::Auto;
  int autoCheckPairs = 64;       ///< Auto: random entries checked against exact double sums
  double autoTolerance = 3e-7;   ///< Auto: largest accepted |R - R_exact| in the check (target 1e-6)
  /// Polled before every frame loaded and every tile computed, from several threads (so it must be
  /// thread-safe); true ends the computation with rcfd::Cancelled. A long database's matrix takes
  /// minutes. Empty: never.
  std::function<bool()> stopRequested = {};
  /// Called as frames are loaded and tiles computed, from several threads (so it must be
  /// thread-safe), with the fraction of the distance matrix's work done, non-decreasing and 1 at the
  /// end of each computation (Auto's rare recomputation in double starts over). Empty: never.
  std::function<void(double)> progress = {};
};

struct RecurrenceMatrix {
  Eigen::MatrixXf R;             ///< N x N, symmetric, unit diagonal, in [0, 1]
  double normalisation = 0.0;    ///< N_alphaG of Eq. (7): the largest D [m3 field^2 for L2]
  RecurrenceNorm norm = RecurrenceNorm::L2;
  std::string field = "alpha_p";
  int frameBlocks = 1;           ///< memory blocks the frames were split into
  std::int64_t clampedNegatives = 0;  ///< round-off D < 0 set to 0 (L2 only)
  double seconds = 0.0;          ///< wall time of the computation
  GramPrecision gramUsed = GramPrecision::Double;  ///< L2: the arithmetic that produced R
  double spotCheckError = 0.0;   ///< Auto: largest |R - R_exact| over the checked entries
  bool autoFellBack = false;     ///< Auto: the float result failed the check; R is the double one
};

/// D(i, j) (before normalisation) for the series; `blocks` and `clamped` report the blocking and the
/// negative round-off values clamped to 0; `stopRequested` and `progress` as in RecurrenceOptions.
Eigen::MatrixXd distanceMatrix(const ScalarSeries& series, RecurrenceNorm norm,
                               std::int64_t memoryBudgetBytes, int tileFrames = 128,
                               int* blocks = nullptr, std::int64_t* clamped = nullptr,
                               GramPrecision precision = GramPrecision::Double,
                               const std::function<bool()>& stopRequested = {},
                               const std::function<void(double)>& progress = {});

/// Eq. (6)-(7) from a distance matrix: R = 1 - D / max D (all ones if every D is 0).
RecurrenceMatrix normaliseDistances(const Eigen::MatrixXd& D);

RecurrenceMatrix computeRecurrenceMatrix(const ScalarSeries& series, const RecurrenceOptions& options);
RecurrenceMatrix computeRecurrenceMatrix(const FieldDatabase& db, const RecurrenceOptions& options = {});

/// Writes R to /recurrence/matrix (float32 [N][N], attributes norm, field, normalisation) of an existing
/// database file opened read-write; replaces an earlier matrix. The file must not be open elsewhere
/// (close FieldDatabase objects first). rcfd::RunError on failure.
void storeRecurrenceMatrix(const std::string& databasePath, const RecurrenceMatrix& matrix);
/// The stored matrix if the file has one of shape [N][N] with N == expectedFrames.
std::optional<RecurrenceMatrix> loadRecurrenceMatrix(const std::string& databasePath, int expectedFrames);
/// Whether loadRecurrenceMatrix() would find one, without reading it.
bool hasStoredRecurrenceMatrix(const std::string& databasePath, int expectedFrames);

/// A diagonal of R: lag k [frames] and the mean of R(i, i + k).
struct RecurrenceLag {
  int lag = 0;
  double meanR = 0.0;
};

struct RecurrenceSummary {
  double meanOffDiagonal = 0.0;
  /// Local maxima of the diagonal means over lags 1..N/2, strongest first.
  std::vector<RecurrenceLag> strongestLags;
  /// Mean of R(i, i + k) for k = 0..N-1.
  std::vector<double> diagonalMeans;
};

RecurrenceSummary summariseRecurrence(const Eigen::MatrixXf& R, int maxLags = 5);

}  // namespace rcfd
