// FieldDatabase::open: validation of the HDF5 layout (docs/formats.md) and the two ways
// of serving frames: all in RAM, or an LRU cache bounded in bytes that reads frames on demand.

#include <atomic>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <mutex>

#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/FieldDatabase.hpp"
#include "fields/FieldValidation.hpp"
#include "fields/FrameCache.hpp"
#include "fields/VelocityCompletion.hpp"

namespace rcfd {

namespace {

using h5::Handle;

/// Everything but the frames: read once at open.
struct Header {
  std::string path;
  CartesianGrid grid;
  std::vector<float> fluidFraction;
  double dtRec = 0.0;
  int frames = 0;
  std::string scene;
  bool velocitySpread = false;  ///< frames carry kVelocitySpreadFields
};

/// Frames held in memory: the RAM mode of a file and makeInMemoryDatabase().
class InRamDatabase final : public FieldDatabase {
 public:
  InRamDatabase(Header header, std::vector<std::shared_ptr<const FieldFrame>> frames)
      : h_(std::move(header)), frames_(std::move(frames)) {
    for (const auto& f : frames_) resident_ += std::int64_t(f->bytes());
  }
  const std::string& path() const override { return h_.path; }
  const CartesianGrid& grid() const override { return h_.grid; }
  const std::vector<float>& fluidFraction() const override { return h_.fluidFraction; }
  double dtRec() const override { return h_.dtRec; }
  int frameCount() const override { return int(frames_.size()); }
  const std::string& sceneJson() const override { return h_.scene; }
  std::shared_ptr<const FieldFrame> frame(int index) const override {
    if (index < 0 || index >= frameCount()) {
      throw std::out_of_range("frame " + std::to_string(index) + " of a database with " +
                              std::to_string(frameCount()) + " frames");
    }
    hits_.fetch_add(1, std::memory_order_relaxed);
    return frames_[std::size_t(index)];
  }
  FrameCacheStats cacheStats() const override {
    return {hits_.load(std::memory_order_relaxed), 0, resident_};
  }
  bool hasVelocitySpread() const override { return h_.velocitySpread; }

 private:
  Header h_;
  std::vector<std::shared_ptr<const FieldFrame>> frames_;
  std::int64_t resident_ = 0;
  mutable std::atomic<std::int64_t> hits_{0};
};

/// The three frame datasets of an open file and how to read frame n of them.
struct FrameReader {
  Handle file;
  Handle alphaP, uP, uG;
  Handle spread[std::size(kVelocitySpreadFields)];  ///< read when valid (FrameStorage::velocitySpread)
  CartesianGrid grid;
  std::vector<float> openFraction;  ///< /grid/fluid_fraction
  std::string path;
  mutable std::mutex io;

  void readPart(hid_t set, const char* name, int index, int components, std::vector<float>& out) const {
    const std::int64_t cells = grid.cellCount();
    out.resize(std::size_t(cells * components));
    Handle space = h5::check(H5Dget_space(set), name);
    std::vector<hsize_t> start(components == 1 ? 4 : 5, 0), count(start.size(), 0);
    start[0] = hsize_t(index);
    count[0] = 1;
    count[1] = hsize_t(grid.shape[2]);
    count[2] = hsize_t(grid.shape[1]);
    count[3] = hsize_t(grid.shape[0]);
    if (components == 3) count[4] = 3;
    h5::checkStatus(H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(),
                                        nullptr),
                    path + ": selecting frame " + std::to_string(index) + " of " + name);
    // The memory space has the selection's shape: with a flat one HDF5 maps element by element
    // between the two shapes (H5S_select_iterate), about 50x slower than a matching shape.
    Handle memory = h5::check(H5Screate_simple(int(count.size()), count.data(), nullptr), name);
    // H5T_NATIVE_FLOAT as memory type: HDF5 converts float64 (or other float) datasets on read.
    if (H5Dread(set, H5T_NATIVE_FLOAT, memory, space, H5P_DEFAULT, out.data()) < 0) {
      throw RunError(path + ": reading frame " + std::to_string(index) + " of " + name + " failed");
    }
  }

  std::shared_ptr<const FieldFrame> read(int index) const {
    auto frame = std::make_shared<FieldFrame>();
    {
      std::lock_guard lock(io);
      readPart(alphaP, layout::alphaP, index, 1, frame->alpha_p);
      readPart(uP, layout::uP, index, 3, frame->u_p);
      readPart(uG, layout::uG, index, 3, frame->u_g);
      for (std::size_t k = 0; k < std::size(kVelocitySpreadFields); ++k) {
        const auto& f = kVelocitySpreadFields[k];
        if (spread[k].valid()) readPart(spread[k], f.path, index, f.components, (*frame).*f.member);
      }
    }
    checkFrame(*frame, index, grid, path);  // NaN/Inf: refused when the frame is read
    completeParticleVelocity(grid, openFraction, cellsWithParticleVolume(*frame), *frame, 1);
    return frame;
  }
};

/// Frames read on demand through a bounded LRU cache; the file stays open.
class CachedDatabase final : public FieldDatabase {
 public:
  CachedDatabase(Header header, std::unique_ptr<FrameReader> reader, std::int64_t cacheBytes)
      : h_(std::move(header)), reader_(std::move(reader)), cache_(cacheBytes) {}
  const std::string& path() const override { return h_.path; }
  const CartesianGrid& grid() const override { return h_.grid; }
  const std::vector<float>& fluidFraction() const override { return h_.fluidFraction; }
  double dtRec() const override { return h_.dtRec; }
  int frameCount() const override { return h_.frames; }
  const std::string& sceneJson() const override { return h_.scene; }
  std::shared_ptr<const FieldFrame> frame(int index) const override {
    if (index < 0 || index >= h_.frames) {
      throw std::out_of_range("frame " + std::to_string(index) + " of a database with " +
                              std::to_string(h_.frames) + " frames");
    }
    return cache_.get(index, [this](int i) { return reader_->read(i); });
  }
  FrameCacheStats cacheStats() const override { return cache_.stats(); }
  bool hasVelocitySpread() const override { return h_.velocitySpread; }

 private:
  Header h_;
  std::unique_ptr<FrameReader> reader_;
  mutable FrameCache cache_;
};

[[noreturn]] void refuse(const std::string& path, std::vector<Violation> violations) {
  throw InputError(path, std::move(violations));
}

std::string dimsText(const std::vector<hsize_t>& dims) {
  std::string s = "[";
  for (std::size_t i = 0; i < dims.size(); ++i) s += (i ? ", " : "") + std::to_string(dims[i]);
  return s + "]";
}

/// Opens a dataset that must exist and hold floating-point values of the given trailing shape;
/// returns its first dimension through `first` (rank = 1 + trailing.size()).
Handle openFloatDataset(hid_t file, const char* name, const std::vector<hsize_t>& trailing,
                        std::vector<Violation>& violations, hsize_t* first) {
  if (!h5::linkExists(file, name)) {
    violations.push_back({name, "dataset is missing"});
    return {};
  }
  Handle set(H5Dopen2(file, name, H5P_DEFAULT));
  if (!set.valid() || H5Iget_type(set) != H5I_DATASET) {
    violations.push_back({name, "is not a dataset"});
    return {};
  }
  if (h5::datasetClass(set) != H5T_FLOAT) {
    violations.push_back({name, "must hold floating-point values (float32; float64 is converted)"});
    return {};
  }
  const auto dims = h5::datasetDims(set);
  const std::size_t rank = trailing.size() + (first ? 1 : 0);
  std::vector<hsize_t> tail(dims.end() - std::min(dims.size(), trailing.size()), dims.end());
  if (dims.size() != rank || tail != trailing) {
    std::string expected = first ? "[N, " : "[";
    for (std::size_t i = 0; i < trailing.size(); ++i) expected += (i ? ", " : "") + std::to_string(trailing[i]);
    violations.push_back({name, "has shape " + dimsText(dims) + "; expected " + expected +
                                    "] (C order [nz][ny][nx], from /grid@shape)"});
    return {};
  }
  if (first) *first = dims[0];
  return set;
}

Header readHeader(hid_t file, const std::string& path) {
  Header h;
  h.path = path;
  std::vector<Violation> v;
  // Root attributes.
  const auto format = h5::readStringAttribute(file, "format");
  if (!format) v.push_back({"/@format", "string attribute is missing; expected \"rcfd-field-database\""});
  else if (*format != layout::formatName)
    v.push_back({"/@format", "is \"" + *format + "\"; expected \"rcfd-field-database\""});
  const auto version = h5::readNumericAttribute(file, "version");
  if (!version || version->size() != 1) v.push_back({"/@version", "integer attribute is missing; expected 1"});
  else if ((*version)[0] != layout::version)
    v.push_back({"/@version", "is " + std::to_string((*version)[0]) + "; this reader knows version 1"});
  const auto dt = h5::readNumericAttribute(file, "dt_rec");
  if (!dt || dt->size() != 1) v.push_back({"/@dt_rec", "numeric attribute is missing (sampling interval [s])"});
  else {
    h.dtRec = (*dt)[0];
    validateDtRec(h.dtRec, v);
  }
  // Scene.
  if (!h5::linkExists(file, layout::scene)) {
    v.push_back({layout::scene, "dataset is missing (a string holding the scene JSON)"});
  } else {
    Handle set(H5Dopen2(file, layout::scene, H5P_DEFAULT));
    auto text = set.valid() ? h5::readStringDataset(set) : std::nullopt;
    if (!text) v.push_back({layout::scene, "must be a scalar string dataset (the scene JSON)"});
    else h.scene = *text;
  }
  // Grid.
  if (!h5::linkExists(file, layout::grid)) {
    v.push_back({layout::grid, "group is missing"});
    refuse(path, std::move(v));
  }
  Handle grid(H5Oopen(file, layout::grid, H5P_DEFAULT));
  const char* names[3] = {"origin", "spacing", "shape"};
  std::vector<double> values[3];
  for (int a = 0; a < 3; ++a) {
    auto x = h5::readNumericAttribute(grid, names[a]);
    if (!x) {
      v.push_back({std::string("/grid@") + names[a], "numeric attribute with 3 values (x, y, z) is missing"});
    } else if (x->size() != 3) {
      v.push_back({std::string("/grid@") + names[a],
                   "has " + std::to_string(x->size()) +
                       " values; the grid is uniform and needs exactly 3, one per axis (x, y, z)"});
    } else {
      values[a] = *x;
    }
  }
  if (!v.empty()) refuse(path, std::move(v));
  for (int d = 0; d < 3; ++d) {
    h.grid.origin[d] = values[0][std::size_t(d)];
    h.grid.spacing[d] = values[1][std::size_t(d)];
    const double n = values[2][std::size_t(d)];
    if (!(std::isfinite(n) && n == std::floor(n) && n >= 1 && n <= 1 << 30)) {
      v.push_back({"/grid@shape", "entry " + std::to_string(d) + " is " + std::to_string(n) +
                                      "; cell counts (nx, ny, nz) must be whole numbers >= 1"});
      h.grid.shape[d] = 1;
    } else {
      h.grid.shape[d] = int(n);
    }
  }
  validateGrid(h.grid, v);
  if (!v.empty()) refuse(path, std::move(v));
  const std::vector<hsize_t> cellDims{hsize_t(h.grid.shape[2]), hsize_t(h.grid.shape[1]),
                                      hsize_t(h.grid.shape[0])};
  Handle fluid = openFloatDataset(file, layout::fluidFraction, cellDims, v, nullptr);
  if (fluid.valid()) {
    h.fluidFraction.resize(std::size_t(h.grid.cellCount()));
    if (H5Dread(fluid, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, h.fluidFraction.data()) < 0) {
      v.push_back({layout::fluidFraction, "could not be read"});
    } else {
      validateFluidFraction(h.fluidFraction, h.grid, v);
    }
  }
  if (!v.empty()) refuse(path, std::move(v));
  return h;
}

}  // namespace

std::shared_ptr<FieldDatabase> FieldDatabase::open(const std::string& path, FrameStorage storage) {
  h5::silenceErrors();
  if (storage.cacheBytes < 0) {
    throw InputError(path, "/rcfd/frame_cache_bytes",
                     std::to_string(storage.cacheBytes) + " is negative; 0 (all in RAM) or a size in bytes");
  }
  if (!std::filesystem::exists(path)) throw InputError(path, "", "file does not exist");
  if (H5Fis_hdf5(path.c_str()) <= 0) throw InputError(path, "", "not an HDF5 file");
  auto reader = std::make_unique<FrameReader>();
  reader->file = Handle(h5::openReadOnlyWaitingForWriter(path));
  if (!reader->file.valid()) {
    throw InputError(path, "", "cannot be opened as HDF5 (damaged, or held open for writing for over a minute)");
  }
  Header h = readHeader(reader->file, path);
  reader->grid = h.grid;
  reader->openFraction = h.fluidFraction;
  reader->path = path;

  std::vector<Violation> v;
  const std::vector<hsize_t> cell{hsize_t(h.grid.shape[2]), hsize_t(h.grid.shape[1]),
                                  hsize_t(h.grid.shape[0])};
  std::vector<hsize_t> vec = cell;
  vec.push_back(3);
  hsize_t nA = 0, nP = 0, nG = 0;
  reader->alphaP = openFloatDataset(reader->file, layout::alphaP, cell, v, &nA);
  reader->uP = openFloatDataset(reader->file, layout::uP, vec, v, &nP);
  reader->uG = openFloatDataset(reader->file, layout::uG, vec, v, &nG);
  hsize_t n = std::min({nA, nP, nG});
  const bool noSpread = std::none_of(std::begin(kVelocitySpreadFields), std::end(kVelocitySpreadFields),
                                     [&](const OptionalFrameField& f) { return h5::linkExists(reader->file, f.path); });
  if (storage.velocitySpread && !(storage.velocitySpreadIfPresent && noSpread)) {
    for (std::size_t k = 0; k < std::size(kVelocitySpreadFields); ++k) {
      const auto& f = kVelocitySpreadFields[k];
      if (!h5::linkExists(reader->file, f.path)) {
        v.push_back({f.path, "dataset is missing: the velocity spread (velocity_streams, langevin_velocity) needs it; the database "
                             "job writes it, a database from elsewhere can add it (docs/formats.md)"});
        continue;
      }
      hsize_t count = 0;
      reader->spread[k] = openFloatDataset(reader->file, f.path, f.components == 1 ? cell : vec, v, &count);
      n = std::min(n, count);
    }
    h.velocitySpread = true;
  }
  if (!v.empty()) refuse(path, std::move(v));
  // Frames written completely: the shortest of the frame datasets, and the writer's count if present
  // (a writer interrupted inside a frame may have extended a dataset without filling it).
  {
    Handle frames(H5Oopen(reader->file, layout::frames, H5P_DEFAULT));
    if (auto count = h5::readNumericAttribute(frames, layout::frameCountAttribute);
        count && count->size() == 1 && (*count)[0] >= 0) {
      n = std::min<hsize_t>(n, hsize_t((*count)[0]));
    }
  }
  if (n < hsize_t(layout::minimumFrames)) {
    refuse(path, {{layout::frames, "holds " + std::to_string(n) + " complete frames; at least " +
                                       std::to_string(layout::minimumFrames) + " are needed"}});
  }
  if (n > hsize_t(1) << 30) refuse(path, {{layout::frames, "holds more than 2^30 frames"}});
  h.frames = int(n);

  if (storage.cacheBytes == 0) {
    std::vector<std::shared_ptr<const FieldFrame>> frames(std::size_t(h.frames));
    for (int i = 0; i < h.frames; ++i) {
      if (storage.stopRequested && storage.stopRequested())
        throw Cancelled("stopped while reading " + path + " into memory (frame " + std::to_string(i) + " of " +
                        std::to_string(h.frames) + ")");
      frames[std::size_t(i)] = reader->read(i);
      if (storage.progress) storage.progress(double(i + 1) / double(h.frames));
    }
    return std::make_shared<InRamDatabase>(std::move(h), std::move(frames));  // closes the file
  }
  const int floats = kFrameFloatsPerCell + (h.velocitySpread ? kVelocitySpreadFloatsPerCell : 0);
  const std::int64_t frameBytes = h.grid.cellCount() * floats * std::int64_t(sizeof(float));
  if (storage.cacheBytes < frameBytes) {
    throw InputError(path, "/rcfd/frame_cache_bytes",
                     std::to_string(storage.cacheBytes) + " bytes cannot hold one frame (" +
                         std::to_string(frameBytes) + " bytes); use 0 (all in RAM) or at least that");
  }
  return std::make_shared<CachedDatabase>(std::move(h), std::move(reader), storage.cacheBytes);
}

std::shared_ptr<FieldDatabase> makeInMemoryDatabase(const CartesianGrid& grid,
                                                    std::vector<float> fluidFraction, double dtRec,
                                                    std::vector<FieldFrame> frames, std::string sceneJson) {
  const std::string source = "(memory)";
  std::vector<Violation> v;
  validateGrid(grid, v);
  validateDtRec(dtRec, v);
  if (v.empty()) validateFluidFraction(fluidFraction, grid, v);
  if (frames.size() < std::size_t(layout::minimumFrames)) {
    v.push_back({layout::frames, "holds " + std::to_string(frames.size()) + " frames; at least " +
                                     std::to_string(layout::minimumFrames) + " are needed"});
  }
  if (!v.empty()) throw InputError(source, std::move(v));
  Header h{source, grid, std::move(fluidFraction), dtRec, int(frames.size()), std::move(sceneJson),
           !frames.empty() && frames.front().hasVelocitySpread()};
  std::vector<std::shared_ptr<const FieldFrame>> shared;
  shared.reserve(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    checkFrame(frames[i], int(i), grid, source);
    if (frames[i].hasVelocitySpread() != h.velocitySpread) {
      throw InputError(source, kVelocitySpreadFields[0].path,
                       "frame " + std::to_string(i) + (h.velocitySpread ? " lacks" : " has") +
                           " the velocity spread that frame 0 " + (h.velocitySpread ? "has" : "lacks"));
    }
    completeParticleVelocity(grid, h.fluidFraction, cellsWithParticleVolume(frames[i]), frames[i], 1);
    shared.push_back(std::make_shared<const FieldFrame>(std::move(frames[i])));
  }
  return std::make_shared<InRamDatabase>(std::move(h), std::move(shared));
}

}  // namespace rcfd
