#pragma once
/// \file Hdf5.hpp
/// Thin RAII over the HDF5 C API (libhdf5 1.10, serial) for the field database and its readers:
/// owned identifiers, attribute and string helpers, and the checks that turn a malformed file into
/// an rcfd::InputError naming the dataset or attribute instead of an HDF5 error stack.

#include <hdf5.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rcfd::hdf5 {

/// An owned HDF5 identifier (file, group, dataset, dataspace, datatype, attribute or property list),
/// closed with the right H5*close on destruction.
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

  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset();
  /// Gives up ownership without closing.
  hid_t release() { return std::exchange(id_, H5I_INVALID_HID); }

 private:
  hid_t id_ = H5I_INVALID_HID;
};

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

}  // namespace rcfd::hdf5
