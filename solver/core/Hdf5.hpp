#pragma once
/// \file Hdf5.hpp
/// Small RAII layer over the HDF5 C API for results and checkpoints: files, groups, 1-D/N-D datasets
/// of double, float and int64, scalar attributes and string datasets. Errors become rcfd::RunError
/// naming the file and object (HDF5's own error stack printing is silenced).

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

namespace rcfd::h5 {

/// An owned hid_t closed with the right H5*close function.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*closer)(hid_t)) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept;
  ~Handle();
  hid_t id() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*closer_)(hid_t) = nullptr;
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

}  // namespace rcfd::h5
