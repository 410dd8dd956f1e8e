#pragma once
// Helpers for the field-database and recurrence tests: temporary files, analytic databases, and a
// database written the way another program (h5py) would, through the raw HDF5 C API with plain
// contiguous datasets and variable-length strings, with switches that break one rule at a time.

#include <hdf5.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/Errors.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "fields/FieldDatabase.hpp"

namespace rcfd::test {

/// A per-process temporary directory, removed when the test program exits normally (forked children
/// leave with _exit and do not remove it).
struct TempDirectory {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("rcfd-test-" + std::to_string(::getpid()));
  TempDirectory() { std::filesystem::create_directories(path); }
  ~TempDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

/// A fresh path in the test program's temporary directory.
inline std::string tempPath(const std::string& name) {
  static TempDirectory dir;
  static std::atomic<int> counter{0};
  return (dir.path / (std::to_string(counter++) + "-" + name)).string();
}

inline CartesianGrid smallGrid(int nx = 4, int ny = 3, int nz = 2, double h = 0.01) {
  CartesianGrid g;
  g.origin = Eigen::Vector3d(-0.02, 0.0, 0.0);
  g.spacing = Eigen::Vector3d(h, h, h);
  g.shape = {nx, ny, nz};
  return g;
}

/// Fluid fractions in (0, 1] with some variety and, if `withClosed`, a few closed cells.
inline std::vector<float> variedFluid(const CartesianGrid& g, bool withClosed = true) {
  std::vector<float> f(std::size_t(g.cellCount()));
  for (std::size_t c = 0; c < f.size(); ++c) {
    f[c] = (withClosed && c % 7 == 3) ? 0.0f : float(0.4 + 0.6 * ((c * 37) % 11) / 10.0);
  }
  return f;
}

/// A deterministic, non-trivial frame n: every value distinct across cells, frames and components.
inline void wavyFrame(const CartesianGrid& g, int n, FieldFrame& f) {
  for (std::int64_t c = 0; c < g.cellCount(); ++c) {
    const double phase = 0.37 * double(c) + 0.11 * n;
    f.alpha_p[std::size_t(c)] = float(0.3 + 0.25 * std::sin(phase) * std::cos(0.05 * n * (1 + c % 3)));
    for (int d = 0; d < 3; ++d) {
      f.u_p[std::size_t(3 * c + d)] = float(std::sin(0.2 * n + c + d) * (d + 1));
      f.u_g[std::size_t(3 * c + d)] = float(std::cos(0.13 * n * (d + 1) + 0.5 * c) * 2.0);
    }
  }
}

inline std::string writeWavyDatabase(const std::string& name, const CartesianGrid& g, int frames,
                                     double dtRec = 0.005) {
  const std::string path = tempPath(name);
  writeAnalyticDatabase(path, g, variedFluid(g), dtRec, frames,
                        [&](int n, double, FieldFrame& f) { wavyFrame(g, n, f); }, "{\"name\":\"test\"}");
  return path;
}

/// What writeRawDatabase() writes and how it breaks the layout.
struct RawSpec {
  int nx = 3, ny = 2, nz = 2;
  int frames = 4;
  double dtRec = 0.01;
  std::vector<double> spacing{0.01, 0.01, 0.01};
  std::vector<double> shapeAttr;     ///< empty: (nx, ny, nz) as int64
  bool shapeAsDouble = false;        ///< write shape as float64 values
  bool framesAsDouble = true;        ///< alpha_p as float64 (readers convert)
  std::string omit;                  ///< dataset or group to leave out, e.g. "/frames/u_g"
  int alphaExtraX = 0;               ///< alpha_p with nx + alphaExtraX columns (wrong shape)
  int nanFrame = -1;                 ///< frame of u_p holding a NaN
  float fluidValue = 1.0f;           ///< fluid fraction of cell 0
  std::string format = "rcfd-field-database";
};

inline float rawValue(int n, int c, int component) { return float(0.1 * n + 0.01 * c + 0.001 * component); }

/// Writes a database like h5py would: variable-length string attributes, int64/float64 attributes,
/// contiguous (unchunked) datasets, no frame_count attribute.
inline void writeRawDatabase(const std::string& path, const RawSpec& s) {
  hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  auto vstr = [] {
    hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    return t;
  };
  auto strAttr = [&](hid_t obj, const char* name, const std::string& value) {
    hid_t t = vstr(), sp = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
    const char* p = value.c_str();
    H5Awrite(a, t, &p);
    H5Aclose(a), H5Sclose(sp), H5Tclose(t);
  };
  auto numAttr = [&](hid_t obj, const char* name, const std::vector<double>& v, bool asInt) {
    hsize_t n = v.size();
    hid_t sp = n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr);
    hid_t a = H5Acreate2(obj, name, asInt ? H5T_STD_I64LE : H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
    std::vector<long long> iv(v.begin(), v.end());
    if (asInt) H5Awrite(a, H5T_NATIVE_LLONG, iv.data());
    else H5Awrite(a, H5T_NATIVE_DOUBLE, v.data());
    H5Aclose(a), H5Sclose(sp);
  };
  auto dataset = [&](const char* name, std::vector<hsize_t> dims, bool asDouble, const std::vector<double>& v) {
    if (s.omit == name) return;
    hid_t sp = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
    hid_t d = H5Dcreate2(file, name, asDouble ? H5T_IEEE_F64LE : H5T_IEEE_F32LE, sp, H5P_DEFAULT,
                         H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(d), H5Sclose(sp);
  };
  strAttr(file, "format", s.format);
  numAttr(file, "version", {1}, true);
  numAttr(file, "dt_rec", {s.dtRec}, false);
  if (s.omit != "/scene") {
    hid_t t = vstr(), sp = H5Screate(H5S_SCALAR);
    hid_t d = H5Dcreate2(file, "/scene", t, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const char* text = "{\"name\": \"from h5py\"}";
    H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &text);
    H5Dclose(d), H5Sclose(sp), H5Tclose(t);
  }
  const int cells = s.nx * s.ny * s.nz;
  if (s.omit != "/grid") {
    hid_t g = H5Gcreate2(file, "/grid", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    numAttr(g, "origin", {0.0, 0.0, 0.0}, false);
    numAttr(g, "spacing", s.spacing, false);
    std::vector<double> shape = s.shapeAttr.empty() ? std::vector<double>{double(s.nx), double(s.ny), double(s.nz)}
                                                    : s.shapeAttr;
    numAttr(g, "shape", shape, !s.shapeAsDouble);
    H5Gclose(g);
    std::vector<double> fluid(std::size_t(cells), 1.0);
    fluid[0] = s.fluidValue;
    dataset("/grid/fluid_fraction", {hsize_t(s.nz), hsize_t(s.ny), hsize_t(s.nx)}, false, fluid);
  }
  hid_t fr = H5Gcreate2(file, "/frames", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Gclose(fr);
  const int nxA = s.nx + s.alphaExtraX;
  std::vector<double> alpha, up, ug;
  for (int n = 0; n < s.frames; ++n)
    for (int c = 0; c < s.nz * s.ny * nxA; ++c) alpha.push_back(rawValue(n, c, 0));
  for (int n = 0; n < s.frames; ++n)
    for (int c = 0; c < cells; ++c)
      for (int d = 0; d < 3; ++d) {
        up.push_back(n == s.nanFrame && c == 1 ? std::nan("") : rawValue(n, c, d + 1));
        ug.push_back(-rawValue(n, c, d + 1));
      }
  dataset("/frames/alpha_p", {hsize_t(s.frames), hsize_t(s.nz), hsize_t(s.ny), hsize_t(nxA)}, s.framesAsDouble, alpha);
  dataset("/frames/u_p", {hsize_t(s.frames), hsize_t(s.nz), hsize_t(s.ny), hsize_t(s.nx), 3}, false, up);
  dataset("/frames/u_g", {hsize_t(s.frames), hsize_t(s.nz), hsize_t(s.ny), hsize_t(s.nx), 3}, false, ug);
  H5Fclose(file);
}

/// Runs `fn`, expecting rcfd::InputError with a violation whose pointer is `pointer`; returns the message.
inline std::string expectInputError(const std::function<void()>& fn, const std::string& pointer) {
  try {
    fn();
  } catch (const InputError& e) {
    for (const auto& v : e.violations())
      if (v.pointer == pointer) return e.what();
    return std::string("WRONG POINTER: ") + e.what();
  } catch (const std::exception& e) {
    return std::string("WRONG EXCEPTION: ") + e.what();
  }
  return "NO EXCEPTION";
}

}  // namespace rcfd::test
