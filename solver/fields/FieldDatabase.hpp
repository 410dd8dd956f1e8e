#pragma once
/// \file FieldDatabase.hpp
/// The recurrence field database (HDF5, layout in docs/formats.md): the scene, the
/// grid with each cell's open fraction, dt_rec, and N frames of alpha_P, u_P and u_G as float32.
/// Written one frame at a time (a crash leaves the frames written so far readable); read either all
/// into RAM or through a bounded LRU frame cache.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "geometry/CartesianGrid.hpp"

namespace rcfd {

/// One sampled state of the full simulation. Cell order: C order, x fastest; vectors interleaved (xyz).
struct FieldFrame {
  std::vector<float> alpha_p;  ///< alpha_P, particle volume fraction [-], one per cell
  std::vector<float> u_p;      ///< u_P, particle velocity [m/s], 3 per cell
  std::vector<float> u_g;      ///< u_G, gas velocity [m/s], 3 per cell

  /// \name Velocity spread (optional, empty when absent or not loaded)
  /// What the volume-weighted mean u_P loses where particles moving up and down share a cell. All
  /// with the mapping weights of u_P, so up_fraction u_p_up + (1 - up_fraction) u_p_down = u_p.
  ///@{
  std::vector<float> up_fraction;   ///< share of the cell's particle volume with u_y > 0 [-], 1 per cell
  std::vector<float> u_p_up;        ///< mean velocity of that volume [m/s], 3 per cell (u_p where none)
  std::vector<float> u_p_down;      ///< mean velocity of the rest (u_y <= 0) [m/s], 3 per cell (u_p where none)
  std::vector<float> u_p_variance;  ///< variance of each velocity component about u_p [m2/s2], 3 per cell
  ///@}
  bool hasVelocitySpread() const { return !up_fraction.empty(); }

  std::size_t bytes() const {
    return (alpha_p.size() + u_p.size() + u_g.size() + up_fraction.size() + u_p_up.size() + u_p_down.size() +
            u_p_variance.size()) *
           sizeof(float);
  }
};

/// The optional per-frame datasets of the velocity spread: one list for the writer, the reader and
/// the validation.
struct OptionalFrameField {
  const char* path;                      ///< dataset in the HDF5 layout
  int components;                        ///< values per cell
  std::vector<float> FieldFrame::*member;
};
inline const OptionalFrameField kVelocitySpreadFields[4] = {
    {"/frames/up_fraction", 1, &FieldFrame::up_fraction},
    {"/frames/u_p_up", 3, &FieldFrame::u_p_up},
    {"/frames/u_p_down", 3, &FieldFrame::u_p_down},
    {"/frames/u_p_variance", 3, &FieldFrame::u_p_variance}};
/// Floats per cell of a frame: alpha_P, u_P, u_G, and the velocity spread when it is held.
inline constexpr int kFrameFloatsPerCell = 7;
inline constexpr int kVelocitySpreadFloatsPerCell = 10;

/// How frames are served: all in RAM (cacheBytes == 0) or through an LRU cache of at most cacheBytes.
struct FrameStorage {
  std::int64_t cacheBytes = 0;
  /// Also read the velocity spread (kVelocitySpreadFields); an input error naming the dataset when the
  /// file has none. Off: those datasets are not read and cost no memory.
  bool velocitySpread = false;
  /// With velocitySpread: a file that holds none of it is opened without it (the readers that use it
  /// when present do without it) instead of refused.
  bool velocitySpreadIfPresent = false;
  /// Polled before each frame read into RAM (cacheBytes == 0: a long database takes minutes); true
  /// ends the open with rcfd::Cancelled. Empty: never.
  std::function<bool()> stopRequested = {};
  /// Called after each frame read into RAM (cacheBytes == 0) with the fraction of the frames read.
  /// Empty: never.
  std::function<void(double)> progress = {};
};

struct FrameCacheStats {
  std::int64_t hits = 0;
  std::int64_t misses = 0;     ///< frames read from disk on demand
  std::int64_t residentBytes = 0;
};

/// Names in the HDF5 layout (docs/formats.md).
namespace layout {
inline constexpr const char* formatName = "rcfd-field-database";
inline constexpr int version = 1;
inline constexpr const char* scene = "/scene";
inline constexpr const char* grid = "/grid";
inline constexpr const char* fluidFraction = "/grid/fluid_fraction";
inline constexpr const char* frames = "/frames";
inline constexpr const char* alphaP = "/frames/alpha_p";
inline constexpr const char* uP = "/frames/u_p";
inline constexpr const char* uG = "/frames/u_g";
/// Optional attribute of /frames: frames completely written, updated after each frame's data.
inline constexpr const char* frameCountAttribute = "frame_count";
inline constexpr const char* recurrenceMatrix = "/recurrence/matrix";
inline constexpr int minimumFrames = 3;
}  // namespace layout

class FieldDatabase {
 public:
  /// Opens and validates a database; rcfd::InputError naming the dataset if it breaks the layout
  /// (missing dataset, wrong shape, NaN in a frame, fewer than 3 frames, bad grid attributes).
  static std::shared_ptr<FieldDatabase> open(const std::string& path, FrameStorage storage = {});

  virtual ~FieldDatabase() = default;
  virtual const std::string& path() const = 0;
  virtual const CartesianGrid& grid() const = 0;
  /// Open volume fraction of each cell [-] (/grid/fluid_fraction).
  virtual const std::vector<float>& fluidFraction() const = 0;
  virtual double dtRec() const = 0;  ///< sampling interval [s]
  virtual int frameCount() const = 0;
  virtual const std::string& sceneJson() const = 0;
  /// Frame `index` (0 <= index < frameCount()); safe to call from several threads. With a frame cache
  /// a frame is validated when first read: rcfd::InputError if it holds NaN/Inf (catch it before it
  /// leaves an OpenMP region); std::out_of_range for a bad index.
  virtual std::shared_ptr<const FieldFrame> frame(int index) const = 0;
  virtual FrameCacheStats cacheStats() const = 0;
  /// Whether the frames served carry the velocity spread (FieldFrame::hasVelocitySpread()).
  virtual bool hasVelocitySpread() const = 0;
  /// Bytes of one frame in memory (FieldFrame::bytes()).
  std::int64_t frameBytes() const {
    const int floats = kFrameFloatsPerCell + (hasVelocitySpread() ? kVelocitySpreadFloatsPerCell : 0);
    return grid().cellCount() * floats * std::int64_t(sizeof(float));
  }
};

/// A database held in memory only (no file): tests and benchmarks of other areas. Validated like a
/// file (sizes, fluid fraction in [0, 1], finite values, at least 3 frames); path() is "(memory)".
std::shared_ptr<FieldDatabase> makeInMemoryDatabase(const CartesianGrid& grid,
                                                    std::vector<float> fluidFraction, double dtRec,
                                                    std::vector<FieldFrame> frames,
                                                    std::string sceneJson = "{}");

/// Storage options of a new database. HDF5's shuffle + deflate filters are off by default: on the
/// paper-size benchmark they cost more load time than the smaller file saves (docs/performance.md).
struct FieldDatabaseWriterOptions {
  int deflateLevel = 0;  ///< 0: no compression; 1-9: deflate level
  bool shuffle = false;  ///< byte shuffle before deflate
  bool velocitySpread = false;  ///< write kVelocitySpreadFields (every appended frame must carry them)
};

/// Appends frames to a new database file; each append is flushed so the file stays readable.
class FieldDatabaseWriter {
 public:
  FieldDatabaseWriter(const std::string& path, const CartesianGrid& grid,
                      const std::vector<float>& fluidFraction, double dtRec,
                      const std::string& sceneJson, FieldDatabaseWriterOptions options = {});
  /// Closes the file if close() was not called (errors are swallowed there; call close() to see them).
  ~FieldDatabaseWriter();
  FieldDatabaseWriter(const FieldDatabaseWriter&) = delete;
  FieldDatabaseWriter& operator=(const FieldDatabaseWriter&) = delete;

  /// Reopens a database file written by this class to go on appending after its first `keepFrames`
  /// frames; frames after them are discarded (the datasets shrink, the frame count follows). What a
  /// resumed job does with frames sampled after its last checkpoint. A stored /recurrence/matrix is
  /// removed (it belongs to the old frames). rcfd::InputError naming the file
  /// and dataset when the file is not a database of `grid` or holds fewer than keepFrames frames.
  static std::unique_ptr<FieldDatabaseWriter> reopen(const std::string& path, const CartesianGrid& grid,
                                                     int keepFrames);

  /// Appends frame framesWritten(); refuses wrongly sized or non-finite frames (rcfd::InputError
  /// naming the dataset). After it returns the frame is on disk (H5Fflush).
  void append(const FieldFrame& frame);
  int framesWritten() const;
  /// Whether appended frames must carry the velocity spread (created so, or reopened on such a file).
  bool writesVelocitySpread() const;
  void close();

 private:
  FieldDatabaseWriter();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rcfd
