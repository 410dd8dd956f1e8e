#pragma once
/// \file OpenFoamMesh.hpp
/// The cell centres and volumes of an OpenFOAM polyMesh (constant/polyMesh/{points,faces,owner,
/// neighbour}), computed as OpenFOAM's primitiveMesh does (primitiveMeshFaceCentresAndAreas.C,
/// primitiveMeshCellCentresAndVols.C): a face's centroid and area vector from a triangle fan about the
/// average of its points, a cell's volume and centroid from the pyramids its faces form with the
/// average of its face centres. Faces may be a `faceList` (ASCII `n(a b c ...)`) or a
/// `faceCompactList` (offsets and labels, what binary meshes hold).

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace rcfd::openfoam {

struct CellGeometry {
  std::vector<Eigen::Vector3d> centres;  ///< cell centroids [m]
  std::vector<double> volumes;           ///< cell volumes [m3], > 0
  std::int64_t cellCount() const { return std::int64_t(volumes.size()); }
  double totalVolume() const;
};

/// Reads `polyMeshDir` (each file plain or .gz) and computes every cell's centroid and volume.
/// rcfd::InputError naming the file when a file is missing or malformed, a face or cell label is out of
/// range, or a cell comes out with a volume <= 0 (an inside-out or broken mesh).
CellGeometry readCellGeometry(const std::filesystem::path& polyMeshDir);

/// The geometry itself, for meshes already in memory: faces as offsets (faces + 1) into `faceLabels`.
/// `source` names the mesh in messages.
CellGeometry computeCellGeometry(const std::vector<Eigen::Vector3d>& points,
                                 const std::vector<std::int64_t>& faceOffsets,
                                 const std::vector<std::int64_t>& faceLabels,
                                 const std::vector<std::int64_t>& owner,
                                 const std::vector<std::int64_t>& neighbour, const std::string& source);

}  // namespace rcfd::openfoam
