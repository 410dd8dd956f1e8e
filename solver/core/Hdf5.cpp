#include "core/Hdf5.hpp"

#include "core/Errors.hpp"

namespace rcfd::h5 {
namespace {
struct SilenceHdf5 {
  SilenceHdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }
};
const SilenceHdf5 silenceHdf5;  // messages come from our exceptions, not HDF5's stack dumps

void check(herr_t status, const std::string& what) {
  if (status < 0) throw RunError("HDF5: " + what);
}
}  // namespace

Handle& Handle::operator=(Handle&& o) noexcept {
  if (this != &o) {
    if (valid() && closer_) closer_(id_);
    id_ = o.id_;
    closer_ = o.closer_;
    o.id_ = H5I_INVALID_HID;
  }
  return *this;
}

Handle::~Handle() {
  if (valid() && closer_) closer_(id_);
}

File::File(const std::string& path, Mode mode) : path_(path) {
  hid_t id = H5I_INVALID_HID;
  switch (mode) {
    case Mode::Create: id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT); break;
    case Mode::ReadOnly: id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT); break;
    case Mode::ReadWrite: id = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT); break;
  }
  if (id < 0) throw RunError("cannot open HDF5 file " + path);
  file_ = Handle(id, H5Fclose);
}

void File::flush() { check(H5Fflush(file_.id(), H5F_SCOPE_GLOBAL), "flush " + path_); }

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
      Handle g(H5Gcreate2(file_.id(), partial.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
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
  check(RCFD_H5_ITERATE(file_.id(), group.c_str(), H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names,
                        H5P_DEFAULT),
        "list " + group + " in " + path_);
#undef RCFD_H5_ITERATE
  return names;
}

void File::copyFrom(const File& from, const std::string& source, const std::string& target) {
  const auto slash = target.rfind('/');
  if (slash != std::string::npos && slash > 0) createGroup(target.substr(0, slash));
  check(H5Ocopy(from.id(), source.c_str(), file_.id(), target.c_str(), H5P_DEFAULT, H5P_DEFAULT),
        "copy " + from.path() + ":" + source + " to " + path_ + ":" + target);
}

void File::hardLink(const std::string& source, const std::string& target) {
  const auto slash = target.rfind('/');
  if (slash != std::string::npos && slash > 0) createGroup(target.substr(0, slash));
  check(H5Lcreate_hard(file_.id(), source.c_str(), file_.id(), target.c_str(), H5P_DEFAULT, H5P_DEFAULT),
        "link " + target + " to " + source + " in " + path_);
}

void File::writeTyped(const std::string& name, hid_t type, const void* data, std::size_t n,
                      const std::vector<hsize_t>& shape) {
  std::vector<hsize_t> dims = shape.empty() ? std::vector<hsize_t>{hsize_t(n)} : shape;
  const auto slash = name.rfind('/');
  if (slash != std::string::npos && slash > 0) createGroup(name.substr(0, slash));
  if (H5Lexists(file_.id(), name.c_str(), H5P_DEFAULT) > 0) {
    check(H5Ldelete(file_.id(), name.c_str(), H5P_DEFAULT), "replace " + name + " in " + path_);
  }
  Handle space(H5Screate_simple(int(dims.size()), dims.data(), nullptr), H5Sclose);
  Handle set(H5Dcreate2(file_.id(), name.c_str(), type, space.id(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!set.valid()) throw RunError("HDF5: cannot create " + name + " in " + path_);
  if (n > 0) check(H5Dwrite(set.id(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "write " + name);
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
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.id(), H5T_VARIABLE);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle set(H5Dcreate2(file_.id(), name.c_str(), type.id(), space.id(), H5P_DEFAULT, H5P_DEFAULT,
                        H5P_DEFAULT), H5Dclose);
  if (!set.valid()) throw RunError("HDF5: cannot create " + name + " in " + path_);
  const char* ptr = text.c_str();
  check(H5Dwrite(set.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &ptr), "write " + name);
}

std::vector<hsize_t> File::shape(const std::string& name) const {
  Handle set(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.valid()) throw RunError("HDF5: no dataset " + name + " in " + path_);
  Handle space(H5Dget_space(set.id()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  std::vector<hsize_t> dims(std::size_t(rank > 0 ? rank : 0));
  if (rank > 0) H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr);
  return dims;
}

std::size_t File::count(const std::string& name) const {
  std::size_t n = 1;
  for (auto d : shape(name)) n *= d;
  return n;
}

void File::readTyped(const std::string& name, hid_t type, void* data, std::size_t) const {
  Handle set(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.valid()) throw RunError("HDF5: no dataset " + name + " in " + path_);
  check(H5Dread(set.id(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "read " + name + " in " + path_);
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
  Handle set(H5Dopen2(file_.id(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.valid()) throw RunError("HDF5: no dataset " + name + " in " + path_);
  Handle type(H5Dget_type(set.id()), H5Tclose);
  if (H5Tis_variable_str(type.id()) > 0) {
    Handle memType(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(memType.id(), H5T_VARIABLE);
    H5Tset_cset(memType.id(), H5Tget_cset(type.id()));  // HDF5 does not convert ASCII <-> UTF-8
    char* ptr = nullptr;
    check(H5Dread(set.id(), memType.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &ptr), "read " + name);
    std::string out = ptr ? ptr : "";
    H5free_memory(ptr);
    return out;
  }
  const std::size_t size = H5Tget_size(type.id());
  std::string out(size, '\0');
  Handle memType(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(memType.id(), size);
  H5Tset_cset(memType.id(), H5Tget_cset(type.id()));
  check(H5Dread(set.id(), memType.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), "read " + name);
  out.resize(out.find('\0') == std::string::npos ? size : out.find('\0'));
  return out;
}

namespace {
Handle openObject(hid_t file, const std::string& object, const std::string& path) {
  hid_t id = H5Oopen(file, object.c_str(), H5P_DEFAULT);
  if (id < 0) throw RunError("HDF5: no object " + object + " in " + path);
  return Handle(id, H5Oclose);
}
void writeAttribute(hid_t obj, const std::string& attr, hid_t type, const void* value) {
  if (H5Aexists(obj, attr.c_str()) > 0) H5Adelete(obj, attr.c_str());
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle a(H5Acreate2(obj, attr.c_str(), type, space.id(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!a.valid() || H5Awrite(a.id(), type, value) < 0) throw RunError("HDF5: cannot write attribute " + attr);
}
}  // namespace

void File::setAttribute(const std::string& object, const std::string& attr, double value) {
  Handle obj = openObject(file_.id(), object, path_);
  writeAttribute(obj.id(), attr, H5T_NATIVE_DOUBLE, &value);
}
void File::setAttribute(const std::string& object, const std::string& attr, std::int64_t value) {
  Handle obj = openObject(file_.id(), object, path_);
  writeAttribute(obj.id(), attr, H5T_NATIVE_INT64, &value);
}
void File::setAttribute(const std::string& object, const std::string& attr, const std::string& value) {
  Handle obj = openObject(file_.id(), object, path_);
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.id(), H5T_VARIABLE);
  const char* ptr = value.c_str();
  writeAttribute(obj.id(), attr, type.id(), &ptr);
}

bool File::hasAttribute(const std::string& object, const std::string& attr) const {
  Handle obj = openObject(file_.id(), object, path_);
  return H5Aexists(obj.id(), attr.c_str()) > 0;
}
double File::doubleAttribute(const std::string& object, const std::string& attr) const {
  Handle obj = openObject(file_.id(), object, path_);
  Handle a(H5Aopen(obj.id(), attr.c_str(), H5P_DEFAULT), H5Aclose);
  double v = 0;
  if (!a.valid() || H5Aread(a.id(), H5T_NATIVE_DOUBLE, &v) < 0)
    throw RunError("HDF5: no attribute " + attr + " on " + object + " in " + path_);
  return v;
}
std::int64_t File::intAttribute(const std::string& object, const std::string& attr) const {
  Handle obj = openObject(file_.id(), object, path_);
  Handle a(H5Aopen(obj.id(), attr.c_str(), H5P_DEFAULT), H5Aclose);
  std::int64_t v = 0;
  if (!a.valid() || H5Aread(a.id(), H5T_NATIVE_INT64, &v) < 0)
    throw RunError("HDF5: no attribute " + attr + " on " + object + " in " + path_);
  return v;
}
std::string File::stringAttribute(const std::string& object, const std::string& attr) const {
  Handle obj = openObject(file_.id(), object, path_);
  Handle a(H5Aopen(obj.id(), attr.c_str(), H5P_DEFAULT), H5Aclose);
  if (!a.valid()) throw RunError("HDF5: no attribute " + attr + " on " + object + " in " + path_);
  Handle type(H5Aget_type(a.id()), H5Tclose);
  if (H5Tis_variable_str(type.id()) > 0) {
    Handle memType(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(memType.id(), H5T_VARIABLE);
    H5Tset_cset(memType.id(), H5Tget_cset(type.id()));  // HDF5 does not convert ASCII <-> UTF-8
    char* ptr = nullptr;
    check(H5Aread(a.id(), memType.id(), &ptr), "read attribute " + attr);
    std::string out = ptr ? ptr : "";
    H5free_memory(ptr);
    return out;
  }
  const std::size_t size = H5Tget_size(type.id());
  std::string out(size, '\0');
  check(H5Aread(a.id(), type.id(), out.data()), "read attribute " + attr);
  out.resize(out.find('\0') == std::string::npos ? size : out.find('\0'));
  return out;
}

}  // namespace rcfd::h5
