#include "import/OpenFoamMesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <string>

#include "core/Errors.hpp"
#include "import/FoamFile.hpp"

namespace rcfd::openfoam {

double CellGeometry::totalVolume() const {
  double sum = 0.0;
  for (double v : volumes) sum += v;
  return sum;
}

CellGeometry computeCellGeometry(const std::vector<Eigen::Vector3d>& points,
                                 const std::vector<std::int64_t>& faceOffsets,
                                 const std::vector<std::int64_t>& faceLabels,
                                 const std::vector<std::int64_t>& owner,
                                 const std::vector<std::int64_t>& neighbour, const std::string& source) {
  const std::int64_t nFaces = std::int64_t(faceOffsets.size()) - 1;
  const std::int64_t nPoints = std::int64_t(points.size());
  if (std::int64_t(owner.size()) != nFaces)
    throw InputError(source + "/owner", "", std::to_string(owner.size()) + " owners for " + std::to_string(nFaces) +
                                                " faces: expected one per face");
  if (std::int64_t(neighbour.size()) > nFaces)
    throw InputError(source + "/neighbour", "", std::to_string(neighbour.size()) + " neighbours for only " +
                                                    std::to_string(nFaces) + " faces");
  std::int64_t nCells = 0;
  for (std::int64_t c : owner) nCells = std::max(nCells, c + 1);
  for (std::int64_t c : neighbour) nCells = std::max(nCells, c + 1);
  for (std::size_t f = 0; f < owner.size(); ++f)
    if (owner[f] < 0) throw InputError(source + "/owner", "face " + std::to_string(f), "negative cell label");
  for (std::size_t f = 0; f < neighbour.size(); ++f)
    if (neighbour[f] < 0) throw InputError(source + "/neighbour", "face " + std::to_string(f), "negative cell label");

  // Face centroids and area vectors: triangle fan about the average point (primitiveMeshFaceCentresAndAreas.C).
  const std::size_t faceCount = std::size_t(nFaces);
  std::vector<Eigen::Vector3d> faceCentre(faceCount), faceArea(faceCount);
  for (std::int64_t f = 0; f < nFaces; ++f) {
    const std::int64_t begin = faceOffsets[std::size_t(f)], end = faceOffsets[std::size_t(f) + 1];
    const std::int64_t n = end - begin;
    if (n < 3)
      throw InputError(source + "/faces", "face " + std::to_string(f),
                       std::to_string(n) + " points: a face needs at least 3");
    const auto point = [&](std::int64_t k) -> const Eigen::Vector3d& {
      const std::int64_t label = faceLabels[std::size_t(begin + k)];
      if (label < 0 || label >= nPoints)
        throw InputError(source + "/faces", "face " + std::to_string(f),
                         "point label " + std::to_string(label) + " outside [0, " + std::to_string(nPoints) + ")");
      return points[std::size_t(label)];
    };
    if (n == 3) {
      faceCentre[std::size_t(f)] = (point(0) + point(1) + point(2)) / 3.0;
      faceArea[std::size_t(f)] = 0.5 * (point(1) - point(0)).cross(point(2) - point(0));
      continue;
    }
    Eigen::Vector3d average = Eigen::Vector3d::Zero();
    for (std::int64_t k = 0; k < n; ++k) average += point(k);
    average /= double(n);
    Eigen::Vector3d sumN = Eigen::Vector3d::Zero(), sumAc = Eigen::Vector3d::Zero();
    double sumA = 0.0;
    for (std::int64_t k = 0; k < n; ++k) {
      const Eigen::Vector3d& here = point(k);
      const Eigen::Vector3d& next = point(k + 1 == n ? 0 : k + 1);
      const Eigen::Vector3d c = here + next + average;  // 3 x the triangle's centroid
      const Eigen::Vector3d normal = (next - here).cross(average - here);
      const double a = normal.norm();
      sumN += normal;
      sumA += a;
      sumAc += a * c;
    }
    faceCentre[std::size_t(f)] = sumA > 1e-300 ? Eigen::Vector3d(sumAc / (3.0 * sumA)) : average;
    faceArea[std::size_t(f)] = 0.5 * sumN;
  }

  // Cell centroids and volumes: pyramids of each face on the cell's estimated centre
  // (primitiveMeshCellCentresAndVols.C).
  std::vector<Eigen::Vector3d> estimate(std::size_t(nCells), Eigen::Vector3d::Zero());
  std::vector<int> faces(std::size_t(nCells), 0);
  for (std::int64_t f = 0; f < nFaces; ++f) {
    estimate[std::size_t(owner[std::size_t(f)])] += faceCentre[std::size_t(f)];
    ++faces[std::size_t(owner[std::size_t(f)])];
  }
  for (std::size_t f = 0; f < neighbour.size(); ++f) {
    estimate[std::size_t(neighbour[f])] += faceCentre[f];
    ++faces[std::size_t(neighbour[f])];
  }
  for (std::int64_t c = 0; c < nCells; ++c) {
    if (faces[std::size_t(c)] < 4)
      throw InputError(source + "/owner", "cell " + std::to_string(c),
                       std::to_string(faces[std::size_t(c)]) + " faces: a closed cell needs at least 4");
    estimate[std::size_t(c)] /= double(faces[std::size_t(c)]);
  }
  CellGeometry g;
  g.centres.assign(std::size_t(nCells), Eigen::Vector3d::Zero());
  g.volumes.assign(std::size_t(nCells), 0.0);
  const auto addPyramid = [&](std::int64_t cell, std::size_t f, double pyramid3Volume) {
    const Eigen::Vector3d centroid = 0.75 * faceCentre[f] + 0.25 * estimate[std::size_t(cell)];
    g.centres[std::size_t(cell)] += pyramid3Volume * centroid;
    g.volumes[std::size_t(cell)] += pyramid3Volume;
  };
  for (std::int64_t f = 0; f < nFaces; ++f) {
    const std::int64_t own = owner[std::size_t(f)];
    addPyramid(own, std::size_t(f), faceArea[std::size_t(f)].dot(faceCentre[std::size_t(f)] - estimate[std::size_t(own)]));
  }
  for (std::size_t f = 0; f < neighbour.size(); ++f) {
    const std::int64_t nei = neighbour[f];
    addPyramid(nei, f, faceArea[f].dot(estimate[std::size_t(nei)] - faceCentre[f]));
  }
  for (std::int64_t c = 0; c < nCells; ++c) {
    const double v3 = g.volumes[std::size_t(c)];
    if (!(v3 > 0.0))
      throw InputError(source, "cell " + std::to_string(c),
                       "volume " + std::to_string(v3 / 3.0) + " m3 <= 0: faces inside out or the cell is not closed");
    g.centres[std::size_t(c)] /= v3;
    g.volumes[std::size_t(c)] = v3 / 3.0;
  }
  return g;
}

CellGeometry readCellGeometry(const std::filesystem::path& polyMeshDir) {
  FoamFile pointsFile = FoamFile::read(polyMeshDir / "points");
  const std::vector<double> xyz = pointsFile.vectorList("points");
  std::vector<Eigen::Vector3d> points(xyz.size() / 3);
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);

  FoamFile facesFile = FoamFile::read(polyMeshDir / "faces");
  std::vector<std::int64_t> offsets, labels;
  if (facesFile.header("class") == "faceCompactList") {
    offsets = facesFile.labelList("faces (offsets)");
    labels = facesFile.labelList("faces (point labels)");
    if (offsets.empty() || offsets.front() != 0 || offsets.back() != std::int64_t(labels.size()) ||
        !std::is_sorted(offsets.begin(), offsets.end()))
      facesFile.fail("faces", "faceCompactList offsets must rise from 0 to the number of point labels (" +
                                  std::to_string(labels.size()) + ")");
  } else {
    facesFile.labelListList("faces", offsets, labels);
  }
  FoamFile ownerFile = FoamFile::read(polyMeshDir / "owner");
  const std::vector<std::int64_t> owner = ownerFile.labelList("owner");
  FoamFile neighbourFile = FoamFile::read(polyMeshDir / "neighbour");
  const std::vector<std::int64_t> neighbour = neighbourFile.labelList("neighbour");
  return computeCellGeometry(points, offsets, labels, owner, neighbour, polyMeshDir.string());
}

}  // namespace rcfd::openfoam
