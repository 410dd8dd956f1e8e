#include "fields/Hdf5.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <thread>

#include "core/Errors.hpp"

namespace rcfd::hdf5 {

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

void silenceErrors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

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

namespace {
std::vector<hsize_t> spaceDims(hid_t space) {
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank <= 0) return {};
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return dims;
}
}  // namespace

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
    Handle memType(H5Tcopy(H5T_C_S1));
    H5Tset_size(memType, H5T_VARIABLE);
    H5Tset_cset(memType, H5Tget_cset(storedType));
    char* text = nullptr;
    if (read(memType.get(), &text) < 0) return std::nullopt;
    std::string out = text ? text : "";
    H5free_memory(text);
    return out;
  }
  const std::size_t size = H5Tget_size(storedType);
  Handle memType(H5Tcopy(H5T_C_S1));
  H5Tset_size(memType, size + 1);
  H5Tset_strpad(memType, H5T_STR_NULLTERM);
  H5Tset_cset(memType, H5Tget_cset(storedType));
  std::string buffer(size + 1, '\0');
  if (read(memType.get(), buffer.data()) < 0) return std::nullopt;
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

}  // namespace rcfd::hdf5
