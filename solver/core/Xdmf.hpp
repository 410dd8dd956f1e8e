#pragma once
/// \file Xdmf.hpp
/// XDMF 3 sidecars: a small XML file beside an HDF5 file of rcfd that tells ParaView (and VisIt) where
/// the cell fields in it live on the Cartesian grid, so `paraview database.xmf` shows grid, arrays and
/// time steps. The XML only points into the HDF5 file (relative path `NAME.h5:/dataset`); no data is
/// copied. docs/formats.md, "ParaView (XDMF sidecars)".

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rcfd::xdmf {

/// The uniform Cartesian grid whose cells the fields belong to, in CartesianGrid's terms: low corner and
/// cell edge lengths (x, y, z) [m], cell counts (nx, ny, nz). Cell (i, j, k) is element [k][j][i] of a
/// field dataset [nz][ny][nx] (C order, x fastest), the layout of every rcfd field.
struct CellGrid {
  std::array<double, 3> origin{};
  std::array<double, 3> spacing{1.0, 1.0, 1.0};
  std::array<std::int64_t, 3> shape{1, 1, 1};
};

/// A 2-D map [ny][nx] of the cells of layer k (a slice at constant z, such as a mid-plane map), shown as
/// a slab one cell thick at that layer so that it sits where its cells are.
struct LayerMap {
  std::string dataset;  ///< absolute dataset path, e.g. "/calibration/recurrence/alpha_p_midplane"
  std::int64_t layer = 0;
};

/// A time series of frames: every dataset [N][nz][ny][nx] (scalar) or [N][nz][ny][nx][3] (vector) directly
/// in `group`, frame n at time n * dt. Datasets with fewer than `frames` frames are left out.
struct FrameSeries {
  std::string group;  ///< e.g. "/frames"
  std::int64_t frames = 0;
  double dt = 0.0;
};

/// `path` with its extension replaced by ".xmf" (result.h5 -> result.xmf).
std::string sidecarPath(const std::string& h5Path);

/// The XDMF document for the HDF5 file `h5Path` (read to find its datasets and their types):
/// - every floating-point or integer dataset of shape [nz][ny][nx] (a scalar) or [nz][ny][nx][3] (a vector)
///   outside the frame group becomes a cell array named by its path without the leading "/"; a dataset
///   reachable under several names (hard links) appears once, under its shortest name;
/// - with `frames`: a temporal collection, one grid per frame with that frame of every series dataset
///   (named by its name in the group) and the time n * dt, each also carrying the static arrays above;
///   without: one grid "cells" holding the static arrays (none if there are none);
/// - one grid per layer of `layerMaps`, holding the maps of that layer.
/// Empty when there is nothing to show (no cell field, no frame, no layer map). Throws rcfd::RunError
/// when the file cannot be read or a layer map is not a [ny][nx] dataset.
std::string sidecarXml(const std::string& h5Path, const CellGrid& grid, const std::vector<LayerMap>& layerMaps = {},
                       const std::optional<FrameSeries>& frames = std::nullopt);

/// Writes sidecarXml() to sidecarPath(h5Path) (through a temporary file and a rename) and returns true;
/// when it is empty, removes a sidecar left there by an earlier run and returns false. Throws
/// rcfd::RunError naming the file when it cannot be written or removed.
bool writeSidecar(const std::string& h5Path, const CellGrid& grid, const std::vector<LayerMap>& layerMaps = {},
                  const std::optional<FrameSeries>& frames = std::nullopt);

}  // namespace rcfd::xdmf
