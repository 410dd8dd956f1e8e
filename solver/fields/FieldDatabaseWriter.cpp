// FieldDatabaseWriter: creates the layout of docs/formats.md and appends one frame at a time. Each append
// extends the three extendible frame datasets (one frame per chunk), writes the frame, then updates
// /frames@frame_count and flushes, so a writer killed between appends leaves a file that reads back
// every completed frame (the default HDF5 superblock keeps no "open for writing" flag that would
// block readers after a crash).

#include <cmath>
#include <iterator>

#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/FieldDatabase.hpp"
#include "fields/FieldValidation.hpp"

namespace rcfd {

using h5::Handle;

struct FieldDatabaseWriter::Impl {
  std::string path;
  CartesianGrid grid;
  Handle file, frames, alphaP, uP, uG;
  Handle spread[std::size(kVelocitySpreadFields)];  ///< the velocity spread's datasets (invalid: not written)
  bool withSpread = false;
  int written = 0;

  Handle createFrameSet(const char* name, int components, const FieldDatabaseWriterOptions& options) {
    const int rank = components == 1 ? 4 : 5;
    hsize_t dims[5] = {0, hsize_t(grid.shape[2]), hsize_t(grid.shape[1]), hsize_t(grid.shape[0]), 3};
    hsize_t maxDims[5] = {H5S_UNLIMITED, dims[1], dims[2], dims[3], 3};
    hsize_t chunk[5] = {1, dims[1], dims[2], dims[3], 3};  // one frame per chunk
    Handle space = h5::check(H5Screate_simple(rank, dims, maxDims), name);
    Handle create = h5::check(H5Pcreate(H5P_DATASET_CREATE), name);
    h5::checkStatus(H5Pset_chunk(create, rank, chunk), std::string(name) + ": chunk layout");
    if (options.shuffle) h5::checkStatus(H5Pset_shuffle(create), std::string(name) + ": shuffle");
    if (options.deflateLevel > 0)
      h5::checkStatus(H5Pset_deflate(create, unsigned(options.deflateLevel)), std::string(name) + ": deflate");
    // Whole chunks are written at once: bypass the chunk cache so each frame goes straight to disk.
    Handle access = h5::check(H5Pcreate(H5P_DATASET_ACCESS), name);
    H5Pset_chunk_cache(access, 0, 0, 1.0);
    return h5::check(H5Dcreate2(file, name, H5T_IEEE_F32LE, space, H5P_DEFAULT, create, access),
                     path + ": creating " + name);
  }

  void appendPart(hid_t set, const char* name, int components, const std::vector<float>& values) {
    hsize_t dims[5] = {hsize_t(written + 1), hsize_t(grid.shape[2]), hsize_t(grid.shape[1]),
                       hsize_t(grid.shape[0]), 3};
    h5::checkStatus(H5Dset_extent(set, dims), path + ": extending " + name);
    Handle space = h5::check(H5Dget_space(set), name);
    hsize_t start[5] = {hsize_t(written), 0, 0, 0, 0};
    hsize_t count[5] = {1, dims[1], dims[2], dims[3], 3};
    h5::checkStatus(H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr), name);
    // Memory space of the selection's shape: HDF5's fast path (a flat space is mapped element-wise).
    Handle memory = h5::check(H5Screate_simple(components == 1 ? 4 : 5, count, nullptr), name);
    if (H5Dwrite(set, H5T_NATIVE_FLOAT, memory, space, H5P_DEFAULT, values.data()) < 0) {
      throw RunError(path + ": writing frame " + std::to_string(written) + " of " + name + " failed");
    }
  }
};

FieldDatabaseWriter::FieldDatabaseWriter(const std::string& path, const CartesianGrid& grid,
                                         const std::vector<float>& fluidFraction, double dtRec,
                                         const std::string& sceneJson, FieldDatabaseWriterOptions options)
    : impl_(std::make_unique<Impl>()) {
  h5::silenceErrors();
  std::vector<Violation> v;
  validateGrid(grid, v);
  validateDtRec(dtRec, v);
  if (v.empty()) validateFluidFraction(fluidFraction, grid, v);
  if (options.deflateLevel < 0 || options.deflateLevel > 9)
    v.push_back({"deflate_level", std::to_string(options.deflateLevel) + " is outside [0, 9]"});
  if (!v.empty()) throw InputError(path, std::move(v));

  Impl& s = *impl_;
  s.path = path;
  s.grid = grid;
  s.file = Handle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT));
  if (!s.file.valid()) throw RunError(path + ": cannot create the database file");
  h5::writeStringAttribute(s.file, "format", layout::formatName);
  h5::writeInt64Attribute(s.file, "version", {layout::version});
  h5::writeDoubleAttribute(s.file, "dt_rec", {dtRec});
  h5::writeStringDataset(s.file, layout::scene, sceneJson);

  Handle g = h5::check(H5Gcreate2(s.file, layout::grid, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/grid");
  h5::writeDoubleAttribute(g, "origin", {grid.origin.x(), grid.origin.y(), grid.origin.z()});
  h5::writeDoubleAttribute(g, "spacing", {grid.spacing.x(), grid.spacing.y(), grid.spacing.z()});
  h5::writeInt64Attribute(g, "shape", {grid.shape[0], grid.shape[1], grid.shape[2]});
  hsize_t cellDims[3] = {hsize_t(grid.shape[2]), hsize_t(grid.shape[1]), hsize_t(grid.shape[0])};
  Handle space = h5::check(H5Screate_simple(3, cellDims, nullptr), layout::fluidFraction);
  Handle fluid = h5::check(H5Dcreate2(s.file, layout::fluidFraction, H5T_IEEE_F32LE, space, H5P_DEFAULT,
                                      H5P_DEFAULT, H5P_DEFAULT),
                           path + ": creating /grid/fluid_fraction");
  h5::checkStatus(H5Dwrite(fluid, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, fluidFraction.data()),
                  path + ": writing /grid/fluid_fraction");

  s.frames = h5::check(H5Gcreate2(s.file, layout::frames, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/frames");
  s.alphaP = s.createFrameSet(layout::alphaP, 1, options);
  s.uP = s.createFrameSet(layout::uP, 3, options);
  s.uG = s.createFrameSet(layout::uG, 3, options);
  s.withSpread = options.velocitySpread;
  if (s.withSpread) {
    for (std::size_t k = 0; k < std::size(kVelocitySpreadFields); ++k) {
      s.spread[k] = s.createFrameSet(kVelocitySpreadFields[k].path, kVelocitySpreadFields[k].components, options);
    }
  }
  h5::setInt64Attribute(s.frames, layout::frameCountAttribute, 0);
  h5::checkStatus(H5Fflush(s.file, H5F_SCOPE_GLOBAL), path + ": flush");
}

FieldDatabaseWriter::FieldDatabaseWriter() : impl_(std::make_unique<Impl>()) {}

std::unique_ptr<FieldDatabaseWriter> FieldDatabaseWriter::reopen(const std::string& path, const CartesianGrid& grid,
                                                                 int keepFrames) {
  h5::silenceErrors();
  std::unique_ptr<FieldDatabaseWriter> w(new FieldDatabaseWriter());
  Impl& s = *w->impl_;
  s.path = path;
  s.grid = grid;
  s.file = Handle(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
  if (!s.file.valid()) throw InputError(path, "", "cannot open the database for appending");
  if (!h5::linkExists(s.file, layout::frames)) throw InputError(path, layout::frames, "missing");
  s.frames = h5::check(H5Gopen2(s.file, layout::frames, H5P_DEFAULT), layout::frames);
  std::int64_t complete = -1;
  if (h5::attributeExists(s.frames, layout::frameCountAttribute)) {
    const auto count = h5::readNumericAttribute(s.frames, layout::frameCountAttribute);
    if (count && !count->empty()) complete = std::int64_t(count->front());
  }
  auto open = [&](const char* name, int components) {
    if (!h5::linkExists(s.file, name)) throw InputError(path, name, "missing");
    Handle access = h5::check(H5Pcreate(H5P_DATASET_ACCESS), name);
    H5Pset_chunk_cache(access, 0, 0, 1.0);
    Handle set = h5::check(H5Dopen2(s.file, name, access), path + ": opening " + name);
    const auto dims = h5::datasetDims(set);
    const std::size_t rank = components == 1 ? 4 : 5;
    const bool shapeOk = dims.size() == rank && dims[1] == hsize_t(grid.shape[2]) &&
                         dims[2] == hsize_t(grid.shape[1]) && dims[3] == hsize_t(grid.shape[0]) &&
                         (rank == 4 || dims[4] == 3);
    if (!shapeOk) throw InputError(path, name, "does not have the frame shape of the job's grid");
    if (complete < 0 || std::int64_t(dims[0]) < complete) complete = std::int64_t(dims[0]);
    return set;
  };
  s.alphaP = open(layout::alphaP, 1);
  s.uP = open(layout::uP, 3);
  s.uG = open(layout::uG, 3);
  // The velocity spread goes on being written when the file has it (all of it: a part is a damaged file).
  std::size_t spreadSets = 0;
  for (const auto& f : kVelocitySpreadFields) spreadSets += h5::linkExists(s.file, f.path) ? 1 : 0;
  if (spreadSets != 0 && spreadSets != std::size(kVelocitySpreadFields)) {
    throw InputError(path, kVelocitySpreadFields[0].path, "the velocity spread is incomplete: " +
                                                              std::to_string(spreadSets) + " of its " +
                                                              std::to_string(std::size(kVelocitySpreadFields)) +
                                                              " datasets exist");
  }
  s.withSpread = spreadSets != 0;
  if (s.withSpread) {
    for (std::size_t k = 0; k < std::size(kVelocitySpreadFields); ++k) {
      s.spread[k] = open(kVelocitySpreadFields[k].path, kVelocitySpreadFields[k].components);
    }
  }
  if (keepFrames < 0 || keepFrames > complete) {
    throw InputError(path, layout::frames, "holds " + std::to_string(complete) + " complete frames; cannot keep " +
                                               std::to_string(keepFrames));
  }
  const hsize_t kept[5] = {hsize_t(keepFrames), hsize_t(grid.shape[2]), hsize_t(grid.shape[1]),
                           hsize_t(grid.shape[0]), 3};
  h5::checkStatus(H5Dset_extent(s.alphaP, kept), path + ": shrinking " + layout::alphaP);
  h5::checkStatus(H5Dset_extent(s.uP, kept), path + ": shrinking " + layout::uP);
  h5::checkStatus(H5Dset_extent(s.uG, kept), path + ": shrinking " + layout::uG);
  if (s.withSpread) {
    for (std::size_t k = 0; k < std::size(kVelocitySpreadFields); ++k) {
      h5::checkStatus(H5Dset_extent(s.spread[k], kept),
                      path + ": shrinking " + kVelocitySpreadFields[k].path);
    }
  }
  s.written = keepFrames;
  // A recurrence matrix computed on the old frames no longer describes the database.
  if (h5::linkExists(s.file, layout::recurrenceMatrix)) {
    h5::checkStatus(H5Ldelete(s.file, layout::recurrenceMatrix, H5P_DEFAULT),
                    path + ": removing the stale " + layout::recurrenceMatrix);
  }
  h5::setInt64Attribute(s.frames, layout::frameCountAttribute, s.written);
  h5::checkStatus(H5Fflush(s.file, H5F_SCOPE_GLOBAL), path + ": flush");
  return w;
}

FieldDatabaseWriter::~FieldDatabaseWriter() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; close() reports errors to callers who want them.
  }
}

void FieldDatabaseWriter::append(const FieldFrame& frame) {
  Impl& s = *impl_;
  if (!s.file.valid()) throw RunError(s.path + ": append after close");
  checkFrame(frame, s.written, s.grid, s.path);
  if (s.withSpread != frame.hasVelocitySpread()) {
    throw InputError(s.path, kVelocitySpreadFields[0].path,
                     std::string("frame ") + std::to_string(s.written) +
                         (s.withSpread ? " carries no velocity spread; this database has one"
                                       : " carries a velocity spread; this database was created without one"));
  }
  s.appendPart(s.alphaP, layout::alphaP, 1, frame.alpha_p);
  s.appendPart(s.uP, layout::uP, 3, frame.u_p);
  s.appendPart(s.uG, layout::uG, 3, frame.u_g);
  if (s.withSpread) {
    for (std::size_t k = 0; k < std::size(kVelocitySpreadFields); ++k) {
      const auto& f = kVelocitySpreadFields[k];
      s.appendPart(s.spread[k], f.path, f.components, frame.*f.member);
    }
  }
  ++s.written;
  // The count goes last: a reader trusts only frames the count covers.
  h5::setInt64Attribute(s.frames, layout::frameCountAttribute, s.written);
  h5::checkStatus(H5Fflush(s.file, H5F_SCOPE_GLOBAL), s.path + ": flush after frame " +
                                                         std::to_string(s.written - 1));
}

int FieldDatabaseWriter::framesWritten() const { return impl_->written; }

bool FieldDatabaseWriter::writesVelocitySpread() const { return impl_->withSpread; }

void FieldDatabaseWriter::close() {
  Impl& s = *impl_;
  if (!s.file.valid()) return;
  s.alphaP.reset();
  s.uP.reset();
  s.uG.reset();
  for (auto& h : s.spread) h.reset();
  s.frames.reset();
  const herr_t status = H5Fclose(s.file.release());
  if (status < 0) throw RunError(s.path + ": closing the database failed");
}

}  // namespace rcfd
