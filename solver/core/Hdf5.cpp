#include "core/Hdf5.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <thread>

#include "core/Errors.hpp"

namespace rcfd::h5 {

void silenceErrors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

namespace {
struct SilenceHdf5 {
  SilenceHdf5() { silenceErrors(); }
};
const SilenceHdf5 silenceHdf5;  // messages come from our exceptions, not HDF5's stack dumps

/// Throws rcfd::RunError("HDF5: what") when an herr_t status is negative (File's wording).
void require(herr_t status, const std::string& what) {
  if (status < 0) throw RunError("HDF5: " + what);
}

std::vector<hsize_t> spaceDims(hid_t space) {
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank <= 0) return {};
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return dims;
}

/// Reads a variable-length string into `out` through `read(memoryType, &text)`, which reads an
/// attribute or a dataset; returns HDF5's status. The memory type keeps the stored character set:
/// HDF5 does not convert ASCII <-> UTF-8.
template <class Read>
herr_t readVariableString(hid_t storedType, std::string& out, Read read) {
  Handle memType(H5Tcopy(H5T_C_S1));
  H5Tset_size(memType, H5T_VARIABLE);
  H5Tset_cset(memType, H5Tget_cset(storedType));
  char* text = nullptr;
  const herr_t status = read(memType.id(), &text);
  if (status >= 0) out = text ? text : "";
  H5free_memory(text);
  return status;
}
}  // namespace

void Handle::reset() {
  if (id_ < 0) return;
  switch (H5Iget_type(id_)) {
    case H5I_FILE: H5Fclose(id_); break;
    case H5I_GROUP: H5Gclose(id_); break;
    case H5I_DATASET: H5Dclose(id_); break;
    case H5I_DATASPACE: H5Sclose(id_); break;
    case H5I_DATATYPE: H5Tclose(id_); break;
    case H5I_ATTR: H5Aclose(id_); break;
    case H5I_GENPROP_LST: H5Pclose(id_); break;
    default: break;
  }
  id_ = H5I_INVALID_HID;
}

File::File(const std::string& path, Mode mode) : path_(path) {
  hid_t id = H5I_INVALID_HID;
  switch (mode) {
    case Mode::Create: id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT); break;
    case Mode::ReadOnly: id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT); break;
    case Mode::ReadWrite: id = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT); break;
  }
  if (id < 0) throw RunError("cannot open HDF5 file " + path);
  file_ = Handle(id);
}

void File::flush() { require(H5Fflush(file_.id(), H5F_SCOPE_GLOBAL), "flush " + path_); }
bool File::exists(const std::string& object) const {
  // Walk the path so a missing parent group answers false instead of raising an error.
  std::string partial;
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    const std::size_t next = object.find('/', pos + 1);
    partial = object.substr(0, next);
    if (!partial.empty() && partial != "/") {
      if (H5Lexists(file_.id(), partial.c_str(), H5P_DEFAULT) <= 0) return false;
    }
    pos = next;
  }
  return true;
}

void File::createGroup(const std::string& group) {
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    const std::size_t next = group.find('/', pos + 1);
    const std::string partial = group.substr(0, next);
    if (!partial.empty() && partial != "/" && H5Lexists(file_.id(), partial.c_str(), H5P_DEFAULT) <= 0) {
      Handle g(H5Gcreate2(file_.id(), partial.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
      if (!g.valid()) throw RunError("HDF5: cannot create group " + partial + " in " + path_);
    }
    pos = next;
  }
}

std::vector<std::string> File::children(const std::string& group) const {
  std::vector<std::string> names;
#if H5_VERSION_GE(1, 12, 0)
  using LinkInfo = H5L_info2_t;
#define RCFD_H5_ITERATE H5Literate_by_name2
#else
  using LinkInfo = H5L_info_t;
#define RCFD_H5_ITERATE H5Literate_by_name
#endif
  auto collect = [](hid_t, const char* name, const LinkInfo*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->push_back(name);
    return 0;
  };
  hsize_t index = 0;
  require(RCFD_H5_ITERATE(file_.id(), group.c_str(), H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names,
                        H5P_DEFAULT),
        "list " + group + " in " + path_);
#undef RCFD_H5_ITERATE
  return names;
}

void File::copyFrom(const File& from, const std::string& source, const std::string& target) {
  const auto slash = target.rfind('/');
  if (slash != std::string::npos && slash > 0) createGroup(target.substr(0, slash));
  require(H5Ocopy(from.id(), source.c_str(), file_.id(), target.c_str(), H5P_DEFAULT, H5P_DEFAULT),
        "copy " + from.path() + ":" + source + " to " + path_ + ":" + target);
}

void File::hardLink(const std::string& source, const std::string& target) {
  const auto slash = target.rfind('/');
  if (slash != std::string::npos && slash > 0) createGroup(target.substr(0, slash));
  require(H5Lcreate_hard(file_.id(), source.c_str(), file_.id(), target.c_str(), H5P_DEFAULT, H5P_DEFAULT),
        "link " + target + " to " + source + " in " + path_);
}

void File::writeTyped(const std::string& name, hid_t type, const void* data, std::size_t n,
                      const std::vector<hsize_t>& shape) {
  std::vector<hsize_t> dims = shape.empty() ? std::vector<hsize_t>{hsize_t(n)} : shape;
  const auto slash = name.rfind('/');
  if (slash != std::string::npos && slash > 0) createGroup(name.substr(0, slash));
  if (H5Lexists(file_.id(), name.c_str(), H5P_DEFAULT) > 0) {
    require(H5Ldelete(file_.id(), name.c_str(), H5P_DEFAULT), "replace " + name + " in " + path_);
  }
  Handle space(H5Screate_simple(int(dims.size()), dims.data(), nullptr));
  Handle set(H5Dcreate2(file_.id(), name.c_str(), type, space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!set.valid()) throw RunError("HDF5: cannot create " + name + " in " + path_);
  if (n > 0) require(H5Dwrite(set.id(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "write " + name);
}

void File::write(const std::string& name, const std::vector<double>& d, const std::vector<hsize_t>& s) {
  writeTyped(name, H5T_NATIVE_DOUBLE, d.data(), d.size(), s);
}
void File::write(const std::string& name, const std::vector<float>& d, const std::vector<hsize_t>& s) {
  writeTyped(name, H5T_NATIVE_FLOAT, d.data(), d.size(), s);
}
void File::write(const std::string& name, const std::vector<std::int64_t>& d,
                 const std::vector<hsize_t>& s) {
  writeTyped(name, H5T_NATIVE_INT64, d.data(), d.size(), s);
}

void File::writeString(const std::string& name, const std::string& text) {
  const auto slash = name.rfind('/');
  if (slash != std::string::npos && slash > 0) createGroup(name.substr(0, slash));
  if (H5Lexists(file_.id(), name.c_str(), H5P_DEFAULT) > 0) H5Ldelete(file_.id(), name.c_str(), H5P_DEFAULT);
  Handle type(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.id(), H5T_VARIABLE);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  Handle space(H5Screate(H5S_SCALAR));
  Handle set(H5Dcreate2(file_.id(), name.c_str(), type.id(), space.id(), H5P_DEFAULT, H5P_DEFAULT,
                        H5P_DEFAULT));
  if (!set.valid()) throw RunError("HDF5: cannot create " + name + " in " + path_);
  const char* ptr = text.c_str();
  require(H5Dwrite(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &ptr), "write " + name);
}

std::vector<hsize_t> File::shape(const std::string& name) const {
  Handle set(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  if (!set.valid()) throw RunError("HDF5: no dataset " + name + " in " + path_);
  return datasetDims(set);
}

std::size_t File::count(const std::string& name) const {
  std::size_t n = 1;
  for (auto d : shape(name)) n *= d;
  return n;
}

void File::readTyped(const std::string& name, hid_t type, void* data, std::size_t) const {
  Handle set(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  if (!set.valid()) throw RunError("HDF5: no dataset " + name + " in " + path_);
  require(H5Dread(set.id(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "read " + name + " in " + path_);
}

std::vector<double> File::readDoubles(const std::string& name) const {
  std::vector<double> v(count(name));
  if (!v.empty()) readTyped(name, H5T_NATIVE_DOUBLE, v.data(), v.size());
  return v;
}
std::vector<float> File::readFloats(const std::string& name) const {
  std::vector<float> v(count(name));
  if (!v.empty()) readTyped(name, H5T_NATIVE_FLOAT, v.data(), v.size());
  return v;
}
std::vector<std::int64_t> File::readInt64s(const std::string& name) const {
  std::vector<std::int64_t> v(count(name));
  if (!v.empty()) readTyped(name, H5T_NATIVE_INT64, v.data(), v.size());
  return v;
}

std::string File::readString(const std::string& name) const {
  Handle set(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT));
  if (!set.valid()) throw RunError("HDF5: no dataset " + name + " in " + path_);
  Handle type(H5Dget_type(set.id()));
  if (H5Tis_variable_str(type.id()) > 0) {
    std::string out;
    require(readVariableString(type.id(), out,
                               [&](hid_t mem, char** text) {
                                 return H5Dread(set.id(), mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, text);
                               }),
            "read " + name);
    return out;
  }
  const std::size_t size = H5Tget_size(type.id());
  std::string out(size, '\0');
  Handle memType(H5Tcopy(H5T_C_S1));
  H5Tset_size(memType.id(), size);
  H5Tset_cset(memType.id(), H5Tget_cset(type.id()));
  require(H5Dread(set.id(), memType.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), "read " + name);
  out.resize(out.find('\0') == std::string::npos ? size : out.find('\0'));
  return out;
}

namespace {
Handle openObject(hid_t file, const std::string& object, const std::string& path) {
  hid_t id = H5Oopen(file, object.c_str(), H5P_DEFAULT);
  if (id < 0) throw RunError("HDF5: no object " + object + " in " + path);
  return Handle(id);
}
/// Writes a scalar attribute stored as `type`, replacing one of that name.
void writeScalarAttribute(hid_t obj, const std::string& attr, hid_t type, const void* value) {
  if (H5Aexists(obj, attr.c_str()) > 0) H5Adelete(obj, attr.c_str());
  Handle space(H5Screate(H5S_SCALAR));
  Handle a(H5Acreate2(obj, attr.c_str(), type, space.id(), H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid() || H5Awrite(a.id(), type, value) < 0) throw RunError("HDF5: cannot write attribute " + attr);
}
}  // namespace

void File::setAttribute(const std::string& object, const std::string& attr, double value) {
  Handle obj = openObject(file_.id(), object, path_);
  writeScalarAttribute(obj.id(), attr, H5T_NATIVE_DOUBLE, &value);
}
void File::setAttribute(const std::string& object, const std::string& attr, std::int64_t value) {
  Handle obj = openObject(file_.id(), object, path_);
  writeScalarAttribute(obj.id(), attr, H5T_NATIVE_INT64, &value);
}
void File::setAttribute(const std::string& object, const std::string& attr, const std::string& value) {
  Handle obj = openObject(file_.id(), object, path_);
  Handle type(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.id(), H5T_VARIABLE);
  const char* ptr = value.c_str();
  writeScalarAttribute(obj.id(), attr, type.id(), &ptr);
}

bool File::hasAttribute(const std::string& object, const std::string& attr) const {
  Handle obj = openObject(file_.id(), object, path_);
  return H5Aexists(obj.id(), attr.c_str()) > 0;
}
double File::doubleAttribute(const std::string& object, const std::string& attr) const {
  Handle obj = openObject(file_.id(), object, path_);
  Handle a(H5Aopen(obj.id(), attr.c_str(), H5P_DEFAULT));
  double v = 0;
  if (!a.valid() || H5Aread(a.id(), H5T_NATIVE_DOUBLE, &v) < 0)
    throw RunError("HDF5: no attribute " + attr + " on " + object + " in " + path_);
  return v;
}
std::int64_t File::intAttribute(const std::string& object, const std::string& attr) const {
  Handle obj = openObject(file_.id(), object, path_);
  Handle a(H5Aopen(obj.id(), attr.c_str(), H5P_DEFAULT));
  std::int64_t v = 0;
  if (!a.valid() || H5Aread(a.id(), H5T_NATIVE_INT64, &v) < 0)
    throw RunError("HDF5: no attribute " + attr + " on " + object + " in " + path_);
  return v;
}
std::string File::stringAttribute(const std::string& object, const std::string& attr) const {
  Handle obj = openObject(file_.id(), object, path_);
  Handle a(H5Aopen(obj.id(), attr.c_str(), H5P_DEFAULT));
  if (!a.valid()) throw RunError("HDF5: no attribute " + attr + " on " + object + " in " + path_);
  Handle type(H5Aget_type(a.id()));
  if (H5Tis_variable_str(type.id()) > 0) {
    std::string out;
    require(readVariableString(type.id(), out, [&](hid_t mem, char** text) { return H5Aread(a.id(), mem, text); }),
            "read attribute " + attr);
    return out;
  }
  const std::size_t size = H5Tget_size(type.id());
  std::string out(size, '\0');
  require(H5Aread(a.id(), type.id(), out.data()), "read attribute " + attr);
  out.resize(out.find('\0') == std::string::npos ? size : out.find('\0'));
  return out;
}

namespace {
/// True while some process holds an exclusive flock on the file (HDF5's lock of a writer).
bool lockedByWriter(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool locked = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);  // also releases the shared lock if it was taken
  return locked;
}
}  // namespace

hid_t openReadOnlyWaitingForWriter(const std::string& path, double patienceSeconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(patienceSeconds);
  for (;;) {
    const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (id >= 0 || !lockedByWriter(path) || std::chrono::steady_clock::now() >= deadline) return id;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

Handle check(hid_t id, const std::string& what) {
  if (id < 0) throw RunError(what + ": HDF5 call failed");
  return Handle(id);
}

void checkStatus(herr_t status, const std::string& what) {
  if (status < 0) throw RunError(what + ": HDF5 call failed");
}

bool linkExists(hid_t location, const std::string& path) {
  // H5Lexists needs every intermediate group to exist: walk the path one component at a time.
  std::string partial;
  std::size_t start = path.front() == '/' ? 1 : 0;
  if (start == 1) partial = "/";
  while (start <= path.size()) {
    const std::size_t end = path.find('/', start);
    const std::string part = path.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (part.empty()) break;
    partial += (partial.empty() || partial.back() == '/' ? "" : "/") + part;
    if (H5Lexists(location, partial.c_str(), H5P_DEFAULT) <= 0) return false;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return true;
}

bool attributeExists(hid_t object, const std::string& name) {
  return H5Aexists(object, name.c_str()) > 0;
}

std::vector<hsize_t> datasetDims(hid_t dataset) {
  Handle space(H5Dget_space(dataset));
  if (!space.valid()) return {};
  return spaceDims(space);
}

std::vector<hsize_t> attributeDims(hid_t attribute) {
  Handle space(H5Aget_space(attribute));
  if (!space.valid()) return {};
  return spaceDims(space);
}

H5T_class_t datasetClass(hid_t dataset) {
  Handle type(H5Dget_type(dataset));
  return type.valid() ? H5Tget_class(type) : H5T_NO_CLASS;
}

namespace {
// Reads a string from an attribute or dataset given its stored type; `read` performs the read with a
// memory type.
template <class Read>
std::optional<std::string> readString(hid_t storedType, hid_t space, Read read) {
  if (H5Tget_class(storedType) != H5T_STRING) return std::nullopt;
  if (H5Sget_simple_extent_npoints(space) != 1) return std::nullopt;
  if (H5Tis_variable_str(storedType) > 0) {
    std::string out;
    if (readVariableString(storedType, out, read) < 0) return std::nullopt;
    return out;
  }
  const std::size_t size = H5Tget_size(storedType);
  Handle memType(H5Tcopy(H5T_C_S1));
  H5Tset_size(memType, size + 1);
  H5Tset_strpad(memType, H5T_STR_NULLTERM);
  H5Tset_cset(memType, H5Tget_cset(storedType));
  std::string buffer(size + 1, '\0');
  if (read(memType.id(), buffer.data()) < 0) return std::nullopt;
  buffer.resize(std::char_traits<char>::length(buffer.c_str()));
  return buffer;
}
}  // namespace

std::optional<std::string> readStringAttribute(hid_t object, const std::string& name) {
  if (!attributeExists(object, name)) return std::nullopt;
  Handle attr(H5Aopen(object, name.c_str(), H5P_DEFAULT));
  if (!attr.valid()) return std::nullopt;
  Handle type(H5Aget_type(attr));
  Handle space(H5Aget_space(attr));
  return readString(type, space, [&](hid_t mem, void* buf) { return H5Aread(attr, mem, buf); });
}

std::optional<std::string> readStringDataset(hid_t dataset) {
  Handle type(H5Dget_type(dataset));
  Handle space(H5Dget_space(dataset));
  return readString(type, space, [&](hid_t mem, void* buf) {
    return H5Dread(dataset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
  });
}

std::optional<std::vector<double>> readNumericAttribute(hid_t object, const std::string& name) {
  if (!attributeExists(object, name)) return std::nullopt;
  Handle attr(H5Aopen(object, name.c_str(), H5P_DEFAULT));
  if (!attr.valid()) return std::nullopt;
  Handle type(H5Aget_type(attr));
  const H5T_class_t cls = H5Tget_class(type);
  if (cls != H5T_INTEGER && cls != H5T_FLOAT) return std::nullopt;
  Handle space(H5Aget_space(attr));
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  if (n < 0) return std::nullopt;
  std::vector<double> values(static_cast<std::size_t>(n));
  if (n > 0 && H5Aread(attr, H5T_NATIVE_DOUBLE, values.data()) < 0) return std::nullopt;
  return values;
}

namespace {
void writeAttribute(hid_t object, const std::string& name, hid_t fileType, hid_t memType,
                    const void* data, hsize_t n, bool scalar) {
  if (attributeExists(object, name)) H5Adelete(object, name.c_str());
  Handle space = scalar ? check(H5Screate(H5S_SCALAR), name) : check(H5Screate_simple(1, &n, nullptr), name);
  Handle attr = check(H5Acreate2(object, name.c_str(), fileType, space, H5P_DEFAULT, H5P_DEFAULT),
                      "creating attribute " + name);
  checkStatus(H5Awrite(attr, memType, data), "writing attribute " + name);
}
}  // namespace

void writeStringAttribute(hid_t object, const std::string& name, const std::string& value) {
  Handle type = check(H5Tcopy(H5T_C_S1), name);
  H5Tset_size(type, value.empty() ? 1 : value.size());
  H5Tset_strpad(type, H5T_STR_NULLPAD);
  H5Tset_cset(type, H5T_CSET_UTF8);
  writeAttribute(object, name, type, type, value.empty() ? "" : value.data(), 1, true);
}

void writeDoubleAttribute(hid_t object, const std::string& name, const std::vector<double>& values) {
  writeAttribute(object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data(), values.size(),
                 values.size() == 1);
}

void writeInt64Attribute(hid_t object, const std::string& name,
                         const std::vector<std::int64_t>& values) {
  writeAttribute(object, name, H5T_STD_I64LE, H5T_NATIVE_INT64, values.data(), values.size(),
                 values.size() == 1);
}

void setInt64Attribute(hid_t object, const std::string& name, std::int64_t value) {
  if (attributeExists(object, name)) {
    Handle attr(H5Aopen(object, name.c_str(), H5P_DEFAULT));
    if (attr.valid() && H5Aget_storage_size(attr) == sizeof(std::int64_t)) {
      checkStatus(H5Awrite(attr, H5T_NATIVE_INT64, &value), "writing attribute " + name);
      return;
    }
  }
  writeInt64Attribute(object, name, {value});
}

void writeStringDataset(hid_t location, const std::string& name, const std::string& value) {
  Handle type = check(H5Tcopy(H5T_C_S1), name);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  Handle space = check(H5Screate(H5S_SCALAR), name);
  Handle set = check(H5Dcreate2(location, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT,
                                H5P_DEFAULT),
                     "creating dataset " + name);
  const char* text = value.c_str();
  checkStatus(H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &text), "writing dataset " + name);
}

}  // namespace rcfd::h5
