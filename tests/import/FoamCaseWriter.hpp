#pragma once
// Writes small OpenFOAM cases for the import tests: a hex lattice mesh (the planes of each axis given),
// vol fields and Lagrangian cloud files, in ASCII or binary, plain or gzip-compressed, as OpenFOAM
// writes them (the FoamFile header, `N (...)` lists, binary `N(raw bytes)` with label=32, scalar=64,
// binary mesh faces as a faceCompactList, binary positions as `(` x y z celli `)` records).

#include <zlib.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace rcfd::test {

// Scene grid: box x in [-0.02, 0.02], y in [0, 0.04], z in [0, 0.01], cells of 0.01 m: 4 x 4 x 1.
// Spray zone: cone from the apex (0, 0, 0.005), half-angle 45 deg, 0.01 <= y <= 0.03.
inline nlohmann::json importTestScene() {
  return nlohmann::json::parse(R"({
    "name": "import-test",
    "apparatus": {"type": "box", "size": [0.04, 0.04, 0.01]},
    "gas": {},
    "grid": {"cell_size": 0.01},
    "particles": {"diameter": 0.001, "density": 1000.0},
    "process": {"bed_mass": 0.001},
    "spray": {"nozzle_position": [0.0, 0.002, 0.005],
              "spray_zone": {"apex": [0.0, 0.0, 0.005], "half_angle_deg": 45, "y_min": 0.01, "y_max": 0.03}},
    "probes": [{"name": "middle", "position": [0.005, 0.015, 0.005]}],
    "effects": []
  })");
}


enum class Encoding { Ascii, Binary };

struct FileStyle {
  Encoding encoding = Encoding::Ascii;
  bool gzip = false;
};

inline std::string foamHeader(const std::string& cls, const std::string& object, Encoding e) {
  std::ostringstream s;
  s << "/*--------------------------------*- C++ -*----------------------------------*\\\n"
    << "  written by the rcfd import tests\n"
    << "\\*---------------------------------------------------------------------------*/\n"
    << "FoamFile\n{\n    version     2.0;\n    format      " << (e == Encoding::Binary ? "binary" : "ascii")
    << ";\n    class       " << cls << ";\n";
  if (e == Encoding::Binary) s << "    arch        \"LSB;label=32;scalar=64\";\n";
  s << "    object      " << object << ";\n}\n// * * * * * * * * * * * * * * * * * * * * * * //\n\n";
  return s.str();
}

inline void writeFoamFile(const std::filesystem::path& path, const std::string& text, bool gzip) {
  std::filesystem::create_directories(path.parent_path());
  if (!gzip) {
    std::ofstream(path, std::ios::binary) << text;
    return;
  }
  gzFile f = gzopen((path.string() + ".gz").c_str(), "wb");
  gzwrite(f, text.data(), unsigned(text.size()));
  gzclose(f);
}

inline std::string scalarBody(const std::vector<double>& v, Encoding e) {
  std::ostringstream s;
  s.precision(17);
  s << v.size() << "\n(";
  if (e == Encoding::Binary) {
    s.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(double)));
  } else {
    s << "\n";
    for (double x : v) s << x << "\n";
  }
  s << ")\n";
  return s.str();
}
inline std::string vectorBody(const std::vector<Eigen::Vector3d>& v, Encoding e) {
  std::ostringstream s;
  s.precision(17);
  s << v.size() << "\n(";
  if (e == Encoding::Binary) {
    for (const auto& x : v) s.write(reinterpret_cast<const char*>(x.data()), 3 * sizeof(double));
  } else {
    s << "\n";
    for (const auto& x : v) s << "(" << x.x() << " " << x.y() << " " << x.z() << ")\n";
  }
  s << ")\n";
  return s.str();
}
inline std::string labelBody(const std::vector<std::int32_t>& v, Encoding e) {
  std::ostringstream s;
  s << v.size() << "\n(";
  if (e == Encoding::Binary) {
    s.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(std::int32_t)));
  } else {
    s << "\n";
    for (auto x : v) s << x << "\n";
  }
  s << ")\n";
  return s.str();
}

/// A hex lattice mesh over the given planes: cell (i, j, k) spans [xs[i], xs[i+1]] x ... ; cells in
/// the order x fastest. Only cells for which `keep(i, j, k)` holds belong to this mesh (a processor's
/// part); faces towards dropped cells become boundary faces.
struct LatticeMesh {
  std::vector<double> xs, ys, zs;
  std::function<bool(int, int, int)> keep = [](int, int, int) { return true; };

  int nx() const { return int(xs.size()) - 1; }
  int ny() const { return int(ys.size()) - 1; }
  int nz() const { return int(zs.size()) - 1; }
  /// Cells of this mesh in its order, as (i, j, k).
  std::vector<std::array<int, 3>> cells() const {
    std::vector<std::array<int, 3>> out;
    for (int k = 0; k < nz(); ++k)
      for (int j = 0; j < ny(); ++j)
        for (int i = 0; i < nx(); ++i)
          if (keep(i, j, k)) out.push_back({i, j, k});
    return out;
  }
  Eigen::Vector3d centre(const std::array<int, 3>& c) const {
    return {0.5 * (xs[c[0]] + xs[c[0] + 1]), 0.5 * (ys[c[1]] + ys[c[1] + 1]), 0.5 * (zs[c[2]] + zs[c[2] + 1])};
  }
  double volume(const std::array<int, 3>& c) const {
    return (xs[c[0] + 1] - xs[c[0]]) * (ys[c[1] + 1] - ys[c[1]]) * (zs[c[2] + 1] - zs[c[2]]);
  }

  void write(const std::filesystem::path& polyMesh, FileStyle style) const {
    const auto pointIndex = [&](int i, int j, int k) { return std::int32_t((k * (ny() + 1) + j) * (nx() + 1) + i); };
    std::vector<Eigen::Vector3d> points;
    for (int k = 0; k <= nz(); ++k)
      for (int j = 0; j <= ny(); ++j)
        for (int i = 0; i <= nx(); ++i) points.emplace_back(xs[i], ys[j], zs[k]);
    const auto cellList = cells();
    std::vector<int> cellIndex(std::size_t(nx() * ny() * nz()), -1);
    for (std::size_t c = 0; c < cellList.size(); ++c)
      cellIndex[std::size_t((cellList[c][2] * ny() + cellList[c][1]) * nx() + cellList[c][0])] = int(c);
    const auto indexOf = [&](int i, int j, int k) {
      if (i < 0 || j < 0 || k < 0 || i >= nx() || j >= ny() || k >= nz()) return -1;
      return cellIndex[std::size_t((k * ny() + j) * nx() + i)];
    };
    struct Face {
      std::vector<std::int32_t> points;
      int owner, neighbour;
    };
    std::vector<Face> internal, boundary;
    // The face on the + side of cell (i, j, k) along axis d, its points ordered so that the normal
    // (right-hand rule) points along +d.
    const auto plusFace = [&](int i, int j, int k, int d) {
      if (d == 0) return std::vector<std::int32_t>{pointIndex(i + 1, j, k), pointIndex(i + 1, j + 1, k),
                                                   pointIndex(i + 1, j + 1, k + 1), pointIndex(i + 1, j, k + 1)};
      if (d == 1) return std::vector<std::int32_t>{pointIndex(i, j + 1, k), pointIndex(i, j + 1, k + 1),
                                                   pointIndex(i + 1, j + 1, k + 1), pointIndex(i + 1, j + 1, k)};
      return std::vector<std::int32_t>{pointIndex(i, j, k + 1), pointIndex(i + 1, j, k + 1),
                                       pointIndex(i + 1, j + 1, k + 1), pointIndex(i, j + 1, k + 1)};
    };
    for (const auto& c : cellList) {
      const int own = indexOf(c[0], c[1], c[2]);
      for (int d = 0; d < 3; ++d) {
        std::array<int, 3> up = c, down = c;
        ++up[d];
        --down[d];
        const int nbUp = indexOf(up[0], up[1], up[2]);
        const auto face = plusFace(c[0], c[1], c[2], d);
        if (nbUp >= 0) internal.push_back({face, own, nbUp});
        else boundary.push_back({face, own, -1});
        if (indexOf(down[0], down[1], down[2]) < 0) {
          auto low = plusFace(down[0], down[1], down[2], d);  // the - face, reversed to point outwards
          std::reverse(low.begin(), low.end());
          boundary.push_back({low, own, -1});
        }
      }
    }
    std::vector<Face> faces = internal;
    faces.insert(faces.end(), boundary.begin(), boundary.end());
    const Encoding e = style.encoding;
    writeFoamFile(polyMesh / "points", foamHeader("vectorField", "points", e) + vectorBody(points, e), style.gzip);
    std::vector<std::int32_t> owner, neighbour;
    for (const auto& f : faces) owner.push_back(f.owner);
    for (const auto& f : internal) neighbour.push_back(f.neighbour);
    writeFoamFile(polyMesh / "owner", foamHeader("labelList", "owner", e) + labelBody(owner, e), style.gzip);
    writeFoamFile(polyMesh / "neighbour", foamHeader("labelList", "neighbour", e) + labelBody(neighbour, e), style.gzip);
    if (e == Encoding::Binary) {
      std::vector<std::int32_t> offsets{0}, labels;
      for (const auto& f : faces) {
        labels.insert(labels.end(), f.points.begin(), f.points.end());
        offsets.push_back(std::int32_t(labels.size()));
      }
      writeFoamFile(polyMesh / "faces",
                    foamHeader("faceCompactList", "faces", e) + labelBody(offsets, e) + labelBody(labels, e), style.gzip);
    } else {
      std::ostringstream s;
      s << faces.size() << "\n(\n";
      for (const auto& f : faces) {
        s << f.points.size() << "(";
        for (std::size_t p = 0; p < f.points.size(); ++p) s << (p ? " " : "") << f.points[p];
        s << ")\n";
      }
      s << ")\n";
      writeFoamFile(polyMesh / "faces", foamHeader("faceList", "faces", e) + s.str(), style.gzip);
    }
  }
};

inline void writeVolVectorField(const std::filesystem::path& file, const std::vector<Eigen::Vector3d>& values,
                                FileStyle style) {
  const std::string name = file.filename().string();
  writeFoamFile(file,
                foamHeader("volVectorField", name, style.encoding) + "dimensions      [0 1 -1 0 0 0 0];\n\n" +
                    "internalField   nonuniform List<vector> " + vectorBody(values, style.encoding) +
                    ";\n\nboundaryField\n{\n    walls\n    {\n        type            noSlip;\n    }\n}\n",
                style.gzip);
}
/// `dimensions` is the field's entry, e.g. "[0 2 -2 0 0 0 0]" for a kinematic pressure.
inline void writeVolScalarField(const std::filesystem::path& file, const std::vector<double>& values, FileStyle style,
                                const std::string& dimensions = "[0 0 0 0 0 0 0]") {
  const std::string name = file.filename().string();
  writeFoamFile(file,
                foamHeader("volScalarField", name, style.encoding) + "dimensions      " + dimensions + ";\n\n" +
                    "internalField   nonuniform List<scalar> " + scalarBody(values, style.encoding) +
                    ";\n\nboundaryField\n{\n    walls\n    {\n        type            zeroGradient;\n    }\n}\n",
                style.gzip);
}

struct TestParcel {
  Eigen::Vector3d x, u;
  double d = 1e-3, nParticle = 1;
  std::int32_t origId = 0, origProcId = 0;
};

/// lagrangian/<cloud>/ files of `parcels` in `cloudDir`; `identities` false leaves origId/origProcId out.
inline void writeCloud(const std::filesystem::path& cloudDir, const std::vector<TestParcel>& parcels, FileStyle style,
                       bool identities = true) {
  const Encoding e = style.encoding;
  std::ostringstream pos;
  pos.precision(17);
  pos << parcels.size() << "\n(\n";
  for (const auto& p : parcels) {
    if (e == Encoding::Binary) {
      pos << "(";
      pos.write(reinterpret_cast<const char*>(p.x.data()), 3 * sizeof(double));
      const std::int32_t cell = 0;
      pos.write(reinterpret_cast<const char*>(&cell), sizeof cell);
      pos << ")\n";
    } else {
      pos << "(" << p.x.x() << " " << p.x.y() << " " << p.x.z() << ") 0\n";
    }
  }
  pos << ")\n";
  writeFoamFile(cloudDir / "positions", foamHeader("Cloud<basicKinematicMPPICParcel>", "positions", e) + pos.str(),
                style.gzip);
  std::vector<Eigen::Vector3d> u;
  std::vector<double> d, n;
  std::vector<std::int32_t> id, proc;
  for (const auto& p : parcels) {
    u.push_back(p.u);
    d.push_back(p.d);
    n.push_back(p.nParticle);
    id.push_back(p.origId);
    proc.push_back(p.origProcId);
  }
  writeFoamFile(cloudDir / "U", foamHeader("vectorField", "U", e) + vectorBody(u, e), style.gzip);
  writeFoamFile(cloudDir / "d", foamHeader("scalarField", "d", e) + scalarBody(d, e), style.gzip);
  writeFoamFile(cloudDir / "nParticle", foamHeader("scalarField", "nParticle", e) + scalarBody(n, e), style.gzip);
  if (identities) {
    writeFoamFile(cloudDir / "origId", foamHeader("labelField", "origId", e) + labelBody(id, e), style.gzip);
    writeFoamFile(cloudDir / "origProcId", foamHeader("labelField", "origProcId", e) + labelBody(proc, e), style.gzip);
  }
}

}  // namespace rcfd::test
