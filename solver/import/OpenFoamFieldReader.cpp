#include "import/OpenFoamFieldReader.hpp"

#include <cmath>
#include <cstring>

#include "core/Errors.hpp"
#include "import/FoamFile.hpp"

namespace rcfd::openfoam {
namespace fs = std::filesystem;

namespace {

std::vector<double> internalField(FoamFile& f, int components, std::int64_t cellCount) {
  const std::string what = "internalField";
  if (!f.seekKeyword(what)) f.fail(what, "no internalField entry");
  const std::string kind = f.word(what);
  std::vector<double> values;
  if (kind == "uniform") {
    std::vector<double> one;
    if (components == 1) {
      one.push_back(f.scalar(what));
    } else {
      f.expect('(', what + " (a uniform vector)");
      for (int c = 0; c < components; ++c) one.push_back(f.scalar(what));
      f.expect(')', what);
    }
    values.reserve(std::size_t(cellCount) * std::size_t(components));
    for (std::int64_t i = 0; i < cellCount; ++i) values.insert(values.end(), one.begin(), one.end());
  } else if (kind == "nonuniform") {
    const std::string type = f.word(what);
    const std::string expected = components == 1 ? "List<scalar>" : "List<vector>";
    if (type != expected) f.fail(what, "expected nonuniform " + expected + ", got " + type);
    values = components == 1 ? f.scalarList(what) : f.vectorList(what);
    if (std::int64_t(values.size()) != cellCount * components)
      f.fail(what, std::to_string(values.size() / std::size_t(components)) + " values for a mesh of " +
                       std::to_string(cellCount) + " cells: expected one per cell");
  } else {
    f.fail(what, "expected uniform or nonuniform, got \"" + kind + "\"");
  }
  if (f.peek() != ';') f.fail(what, "expected ';' after the internalField value");
  return values;
}

}  // namespace

std::vector<double> readInternalField(const fs::path& file, int components, std::int64_t cellCount) {
  FoamFile f = FoamFile::read(file);
  return internalField(f, components, cellCount);
}

std::vector<double> readInternalField(const fs::path& file, int components, std::int64_t cellCount,
                                      Dimensions& dimensions) {
  FoamFile f = FoamFile::read(file);
  const std::string what = "dimensions";
  if (!f.seekKeyword(what)) f.fail(what, "no dimensions entry");
  f.expect('[', what);
  dimensions.fill(0.0);
  std::size_t given = 0;
  while (f.peek() != ']') {
    if (given == dimensions.size()) f.fail(what, "more than 7 exponents");
    dimensions[given++] = f.scalar(what);
  }
  f.expect(']', what);
  if (given != 5 && given != 7) f.fail(what, std::to_string(given) + " exponents: expected 5 or 7");
  return internalField(f, components, cellCount);
}

namespace {

/// The legacy `positions` file: `N ( (x y z) celli ... )` in ASCII, or in binary per parcel `(` the
/// raw position (3 scalars) and cell (a label) `)` (OpenFOAM particleIO.C, writePosition).
std::vector<double> readPositions(const fs::path& file) {
  FoamFile f = FoamFile::read(file);
  const std::string what = "positions";
  const std::int64_t n = f.label(what + " size");
  if (n < 0) f.fail(what, "expected a parcel count >= 0");
  std::vector<double> xyz;
  xyz.reserve(std::size_t(n) * 3);
  f.expect('(', what);
  const std::size_t recordBytes = std::size_t(3 * f.scalarBytes() + f.labelBytes());
  for (std::int64_t i = 0; i < n; ++i) {
    if (f.binary()) {
      const char* p = f.rawRecord(recordBytes, what + " parcel " + std::to_string(i));
      for (int c = 0; c < 3; ++c) {
        double v;
        if (f.scalarBytes() == 8) std::memcpy(&v, p + 8 * c, 8);
        else { float s; std::memcpy(&s, p + 4 * c, 4); v = s; }
        if (!std::isfinite(v)) f.fail(what, "parcel " + std::to_string(i) + ": position not finite");
        xyz.push_back(v);
      }
      continue;
    }
    const std::string item = what + " parcel " + std::to_string(i);
    f.expect('(', item);
    for (int c = 0; c < 3; ++c) xyz.push_back(f.scalar(item));
    if (f.peek() != ')')
      f.fail(item, "expected ')' after x y z: more than 3 coordinates means barycentric positions (OpenFOAM-dev); "
                   "rcfd reads the legacy form \"(x y z) celli\"");
    f.expect(')', item);
    f.label(item + " cell");
  }
  if (f.peek() != ')') f.fail(what, "expected ')' after " + std::to_string(n) + " parcels");
  return xyz;
}

template <class T>
void requireCount(const std::vector<T>& values, std::size_t perParcel, std::size_t parcels, const fs::path& file) {
  if (values.size() != parcels * perParcel)
    throw InputError(file.string(), "", std::to_string(values.size() / perParcel) + " values for " +
                                            std::to_string(parcels) + " parcels in positions: expected one per parcel");
}

}  // namespace

CloudParcels readCloud(const fs::path& cloudDir) {
  CloudParcels c;
  if (!FoamFile::locate(cloudDir / "positions")) {
    if (FoamFile::locate(cloudDir / "coordinates"))
      throw InputError((cloudDir / "coordinates").string(), "",
                       "only barycentric particle coordinates were written, rcfd reads the legacy positions file "
                       "\"(x y z) celli\": write it with \"writeLagrangianPositions 1;\" in the InfoSwitches of "
                       "system/controlDict (ESI OpenFOAM; its default) and run again, or convert the written times");
    throw InputError((cloudDir / "positions").string(), "", "no such file (nor positions.gz): the cloud's parcel positions");
  }
  c.position = readPositions(cloudDir / "positions");
  const std::size_t n = c.position.size() / 3;
  {
    FoamFile f = FoamFile::read(cloudDir / "U");
    c.velocity = f.vectorList("U");
    requireCount(c.velocity, 3, n, f.path());
  }
  {
    FoamFile f = FoamFile::read(cloudDir / "d");
    c.diameter = f.scalarList("d");
    requireCount(c.diameter, 1, n, f.path());
    for (std::size_t i = 0; i < n; ++i)
      if (!(c.diameter[i] > 0.0)) f.fail("d", "parcel " + std::to_string(i) + ": diameter must be > 0 m");
  }
  if (FoamFile::locate(cloudDir / "nParticle")) {
    FoamFile f = FoamFile::read(cloudDir / "nParticle");
    c.nParticle = f.scalarList("nParticle");
    requireCount(c.nParticle, 1, n, f.path());
    for (std::size_t i = 0; i < n; ++i)
      if (!(c.nParticle[i] >= 0.0)) f.fail("nParticle", "parcel " + std::to_string(i) + ": must be >= 0");
  } else {
    c.nParticle.assign(n, 1.0);  // one particle per parcel (a DEM cloud)
  }
  if (FoamFile::locate(cloudDir / "origId")) {
    FoamFile f = FoamFile::read(cloudDir / "origId");
    c.origId = f.labelList("origId");
    requireCount(c.origId, 1, n, f.path());
    if (FoamFile::locate(cloudDir / "origProcId")) {
      FoamFile p = FoamFile::read(cloudDir / "origProcId");
      c.origProcId = p.labelList("origProcId");
      requireCount(c.origProcId, 1, n, p.path());
    }
  }
  return c;
}

}  // namespace rcfd::openfoam
