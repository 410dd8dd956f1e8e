#pragma once
/// \file Hdf5.hpp
/// Small RAII layer over the HDF5 C API (libhdf5 1.10, serial). File serves results and checkpoints:
/// files, groups, 1-D/N-D datasets of double, float and int64, scalar attributes and string datasets,
/// with errors as rcfd::RunError naming the file and object. The free helpers below serve readers and
/// writers of files that must keep a fixed layout (the field database): attribute and string access,
/// and the checks that let a malformed file become an rcfd::InputError naming the dataset or attribute
/// instead of an HDF5 error stack. HDF5's own error-stack printing is silenced.

#include <hdf5.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rcfd::h5 {

/// An owned HDF5 identifier (file, group, dataset, dataspace, datatype, attribute or property list),
/// closed on destruction with the H5*close its type (H5Iget_type) calls for. Converts to hid_t, so it
/// can be handed straight to the C API.
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id) : id_(id) {}
  Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }

  hid_t id() const { return id_; }
  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }
  /// Closes the identifier now (if any); the handle becomes invalid.
  void reset();
  /// Gives up ownership without closing.
  hid_t release() { return std::exchange(id_, H5I_INVALID_HID); }

 private:
  hid_t id_ = H5I_INVALID_HID;
};

class File {
 public:
  enum class Mode { Create, ReadOnly, ReadWrite };
  File(const std::string& path, Mode mode);
  const std::string& path() const { return path_; }
  hid_t id() const { return file_.id(); }
  void flush();

  bool exists(const std::string& object) const;
  /// Creates the group and its parents if missing.
  void createGroup(const std::string& group);
  /// Names of the links directly in `group`, in name order.
  std::vector<std::string> children(const std::string& group) const;
  /// Copies object `source` of `from` (a dataset, or a group with everything in it) to `target` here.
  void copyFrom(const File& from, const std::string& source, const std::string& target);
  /// A second name `target` for the object `source` of this file (a hard link: no data is copied).
  void hardLink(const std::string& source, const std::string& target);

  void write(const std::string& name, const std::vector<double>& data,
             const std::vector<hsize_t>& shape = {});
  void write(const std::string& name, const std::vector<float>& data,
             const std::vector<hsize_t>& shape = {});
  void write(const std::string& name, const std::vector<std::int64_t>& data,
             const std::vector<hsize_t>& shape = {});
  void writeString(const std::string& name, const std::string& text);

  std::vector<double> readDoubles(const std::string& name) const;
  std::vector<float> readFloats(const std::string& name) const;
  std::vector<std::int64_t> readInt64s(const std::string& name) const;
  std::string readString(const std::string& name) const;
  std::vector<hsize_t> shape(const std::string& name) const;

  void setAttribute(const std::string& object, const std::string& attr, double value);
  void setAttribute(const std::string& object, const std::string& attr, std::int64_t value);
  void setAttribute(const std::string& object, const std::string& attr, const std::string& value);
  bool hasAttribute(const std::string& object, const std::string& attr) const;
  double doubleAttribute(const std::string& object, const std::string& attr) const;
  std::int64_t intAttribute(const std::string& object, const std::string& attr) const;
  std::string stringAttribute(const std::string& object, const std::string& attr) const;

 private:
  std::string path_;
  Handle file_;
  void writeTyped(const std::string& name, hid_t type, const void* data, std::size_t count,
                  const std::vector<hsize_t>& shape);
  void readTyped(const std::string& name, hid_t type, void* data, std::size_t count) const;
  std::size_t count(const std::string& name) const;
};

// Low-level helpers for readers of files written elsewhere (the field database).

/// Turns HDF5's automatic error-stack printing off (errors are reported through rcfd exceptions).
void silenceErrors();

/// H5Fopen(path, read-only). While another process holds the file open for writing (HDF5's file lock,
/// an exclusive flock: a job storing its recurrence matrix in a database others also read), waits and
/// tries again, for up to `patienceSeconds`; a file that fails to open for any other reason fails at
/// once. Returns the file identifier, negative on failure.
hid_t openReadOnlyWaitingForWriter(const std::string& path, double patienceSeconds = 60.0);

/// Throws rcfd::RunError("what: HDF5 call failed") when `id` is negative; returns the owned handle.
Handle check(hid_t id, const std::string& what);
/// Throws rcfd::RunError when an herr_t status is negative.
void checkStatus(herr_t status, const std::string& what);

/// Whether `path` (absolute, or relative to `location`) names a link; a missing parent group answers
/// false instead of raising an error.
bool linkExists(hid_t location, const std::string& path);
bool attributeExists(hid_t object, const std::string& name);

/// Dimensions of a dataset's or attribute's dataspace (empty for a scalar).
std::vector<hsize_t> datasetDims(hid_t dataset);
std::vector<hsize_t> attributeDims(hid_t attribute);

/// H5T_class of a dataset's stored type (H5T_FLOAT, H5T_INTEGER, H5T_STRING, ...).
H5T_class_t datasetClass(hid_t dataset);

/// Reads a string attribute or dataset stored as fixed- or variable-length string (h5py writes
/// variable-length UTF-8 by default); std::nullopt if it is not a string.
std::optional<std::string> readStringAttribute(hid_t object, const std::string& name);
std::optional<std::string> readStringDataset(hid_t dataset);

/// Reads a numeric attribute of any integer or floating type as doubles (HDF5 converts); empty optional
/// if the attribute is not numeric.
std::optional<std::vector<double>> readNumericAttribute(hid_t object, const std::string& name);

void writeStringAttribute(hid_t object, const std::string& name, const std::string& value);
void writeDoubleAttribute(hid_t object, const std::string& name, const std::vector<double>& values);
void writeInt64Attribute(hid_t object, const std::string& name, const std::vector<std::int64_t>& values);
/// Writes (or overwrites) a scalar int64 attribute in place.
void setInt64Attribute(hid_t object, const std::string& name, std::int64_t value);
void writeStringDataset(hid_t location, const std::string& name, const std::string& value);

}  // namespace rcfd::h5
