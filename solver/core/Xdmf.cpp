#include "core/Xdmf.hpp"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/Errors.hpp"
#include "core/Hdf5.hpp"

namespace rcfd::xdmf {
namespace {

/// A dataset as the sidecar needs it: where, its shape, and its element type in XDMF's words.
struct DatasetInfo {
  std::string path;  ///< absolute, e.g. "/fields/alpha_p_mean"
  std::vector<hsize_t> dims;
  std::string numberType;  ///< "Float", "Int" or "UInt"
  std::size_t precision = 0;  ///< bytes per element
};

/// Every numeric dataset of the file, each once: a dataset with several hard links (an ensemble's
/// member 00 links the root's datasets) under its shortest path, ties broken by name.
std::vector<DatasetInfo> numericDatasets(const std::string& h5Path) {
  const hid_t rawId = h5::openReadOnlyWaitingForWriter(h5Path);
  if (rawId < 0) throw RunError("cannot open HDF5 file " + h5Path + " to describe it in its XDMF sidecar");
  const h5::Handle file(rawId);

  // Object identity of each hard link -> its paths.
  std::map<std::string, std::vector<std::string>> pathsOfObject;
#if H5_VERSION_GE(1, 12, 0)
  using LinkInfo = H5L_info2_t;
#define RCFD_H5_LVISIT H5Lvisit2
#else
  using LinkInfo = H5L_info_t;
#define RCFD_H5_LVISIT H5Lvisit
#endif
  auto collect = [](hid_t, const char* name, const LinkInfo* info, void* data) -> herr_t {
    if (info->type != H5L_TYPE_HARD) return 0;
#if H5_VERSION_GE(1, 12, 0)
    const std::string identity(reinterpret_cast<const char*>(&info->u.token), sizeof(info->u.token));
#else
    const std::string identity = std::to_string(info->u.address);
#endif
    (*static_cast<std::map<std::string, std::vector<std::string>>*>(data))[identity].push_back("/" + std::string(name));
    return 0;
  };
  h5::checkStatus(RCFD_H5_LVISIT(file, H5_INDEX_NAME, H5_ITER_INC, collect, &pathsOfObject),
                  "list the objects of " + h5Path);
#undef RCFD_H5_LVISIT

  std::vector<DatasetInfo> out;
  for (auto& [identity, paths] : pathsOfObject) {
    const auto shortest = std::min_element(paths.begin(), paths.end(), [](const std::string& a, const std::string& b) {
      const auto depthA = std::count(a.begin(), a.end(), '/'), depthB = std::count(b.begin(), b.end(), '/');
      return depthA != depthB ? depthA < depthB : a < b;
    });
    const h5::Handle object(H5Oopen(file, shortest->c_str(), H5P_DEFAULT));
    if (!object.valid() || H5Iget_type(object) != H5I_DATASET) continue;
    const h5::Handle type(H5Dget_type(object));
    if (!type.valid()) continue;
    DatasetInfo d;
    d.path = *shortest;
    d.dims = h5::datasetDims(object);
    d.precision = H5Tget_size(type);
    switch (H5Tget_class(type)) {
      case H5T_FLOAT: d.numberType = "Float"; break;
      case H5T_INTEGER: d.numberType = H5Tget_sign(type) == H5T_SGN_NONE ? "UInt" : "Int"; break;
      default: continue;
    }
    out.push_back(std::move(d));
  }
  std::sort(out.begin(), out.end(), [](const DatasetInfo& a, const DatasetInfo& b) { return a.path < b.path; });
  return out;
}

std::string escapeXml(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// Numbers as XML text: the shortest form that reads back to the same value, never the locale's comma.
template <class T>
std::string number(T value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

template <class Sequence>
std::string joined(const Sequence& values) {
  std::string out;
  for (const auto& v : values) out += (out.empty() ? "" : " ") + number(v);
  return out;
}

std::vector<hsize_t> cellDims(const CellGrid& g) {
  return {hsize_t(g.shape[2]), hsize_t(g.shape[1]), hsize_t(g.shape[0])};
}

/// Shape [nz][ny][nx] or [nz][ny][nx][3] after dropping `leading` leading dimensions; the attribute type
/// ("Scalar" or "Vector") or empty when the dataset is no cell field.
std::string cellFieldType(const std::vector<hsize_t>& dims, std::size_t leading, const CellGrid& g) {
  if (dims.size() < leading + 3) return {};
  const std::vector<hsize_t> cells = cellDims(g);
  if (!std::equal(cells.begin(), cells.end(), dims.begin() + std::ptrdiff_t(leading))) return {};
  if (dims.size() == leading + 3) return "Scalar";
  if (dims.size() == leading + 4 && dims.back() == 3) return "Vector";
  return {};
}

class Writer {
 public:
  explicit Writer(std::string fileName) : fileName_(std::move(fileName)) {}

  void line(int indent, const std::string& text) { xml_ << std::string(std::size_t(indent) * 2, ' ') << text << '\n'; }

  /// Topology and geometry of `cells` (nx, ny, nz) cells from `origin`; XDMF lists both slowest axis first (z y x).
  void mesh(int indent, const CellGrid& g, const std::array<double, 3>& origin, const std::array<std::int64_t, 3>& cells) {
    line(indent, "<Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" +
                     joined(std::array<std::int64_t, 3>{cells[2] + 1, cells[1] + 1, cells[0] + 1}) + "\"/>");
    line(indent, "<Geometry GeometryType=\"ORIGIN_DXDYDZ\">");
    line(indent + 1, "<DataItem Name=\"Origin\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">" +
                         joined(std::array<double, 3>{origin[2], origin[1], origin[0]}) + "</DataItem>");
    line(indent + 1, "<DataItem Name=\"Spacing\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">" +
                         joined(std::array<double, 3>{g.spacing[2], g.spacing[1], g.spacing[0]}) + "</DataItem>");
    line(indent, "</Geometry>");
  }

  std::string heavyData(const DatasetInfo& d, const std::vector<hsize_t>& dims) const {
    return "<DataItem Dimensions=\"" + joined(dims) + "\" NumberType=\"" + d.numberType + "\" Precision=\"" +
           number(d.precision) + "\" Format=\"HDF\">" + escapeXml(fileName_ + ":" + d.path) + "</DataItem>";
  }

  void attributeStart(int indent, const std::string& name, const std::string& type) {
    line(indent, "<Attribute Name=\"" + escapeXml(name) + "\" AttributeType=\"" + type + "\" Center=\"Cell\">");
  }

  /// The whole dataset, read as `dims` (its own dimensions, or the same values with a leading 1).
  void wholeAttribute(int indent, const std::string& name, const std::string& type, const DatasetInfo& d,
                      const std::vector<hsize_t>& dims) {
    attributeStart(indent, name, type);
    line(indent + 1, heavyData(d, dims));
    line(indent, "</Attribute>");
  }

  /// Frame `n` of a series dataset [N][...]: the selection start:stride:count:dataspace after a "|", the
  /// Xdmf 3 library's form of a hyperslab (ParaView's Xdmf3 readers skip an ItemType="HyperSlab" item).
  void frameAttribute(int indent, const std::string& name, const std::string& type, const DatasetInfo& d,
                      std::int64_t n) {
    const std::vector<hsize_t> frame(d.dims.begin() + 1, d.dims.end());
    std::vector<hsize_t> start(d.dims.size(), 0), stride(d.dims.size(), 1), count = d.dims;
    start[0] = hsize_t(n);
    count[0] = 1;
    attributeStart(indent, name, type);
    line(indent + 1, "<DataItem Dimensions=\"" + joined(frame) + "\" NumberType=\"" + d.numberType +
                         "\" Precision=\"" + number(d.precision) + "\" Format=\"HDF\">" +
                         escapeXml(fileName_ + ":" + d.path + "|" + joined(start) + ":" + joined(stride) + ":" +
                                   joined(count) + ":" + joined(d.dims)) +
                         "</DataItem>");
    line(indent, "</Attribute>");
  }

  std::string text() const { return xml_.str(); }

 private:
  std::string fileName_;
  std::ostringstream xml_;
};

std::string relativeName(const DatasetInfo& d) { return d.path.substr(1); }

}  // namespace

std::string sidecarPath(const std::string& h5Path) {
  return std::filesystem::path(h5Path).replace_extension(".xmf").string();
}

std::string sidecarXml(const std::string& h5Path, const CellGrid& g, const std::vector<LayerMap>& layerMaps,
                       const std::optional<FrameSeries>& frames) {
  const std::vector<DatasetInfo> datasets = numericDatasets(h5Path);
  const std::string groupPrefix = frames ? frames->group + "/" : std::string();

  struct Field {
    const DatasetInfo* data;
    std::string type;
  };
  std::vector<Field> statics, series;
  for (const DatasetInfo& d : datasets) {
    const bool inSeriesGroup = frames && d.path.rfind(groupPrefix, 0) == 0;
    if (inSeriesGroup) {
      const bool direct = d.path.find('/', groupPrefix.size()) == std::string::npos;
      const std::string type = cellFieldType(d.dims, 1, g);
      if (direct && !type.empty() && std::int64_t(d.dims[0]) >= frames->frames) series.push_back({&d, type});
    } else if (const std::string type = cellFieldType(d.dims, 0, g); !type.empty()) {
      statics.push_back({&d, type});
    }
  }

  if (statics.empty() && series.empty() && layerMaps.empty()) return {};

  Writer w(std::filesystem::path(h5Path).filename().string());
  w.line(0, "<?xml version=\"1.0\" encoding=\"utf-8\"?>");
  w.line(0, "<Xdmf Version=\"3.0\">");
  w.line(1, "<Domain>");
  auto staticAttributes = [&](int indent) {
    for (const Field& f : statics) w.wholeAttribute(indent, relativeName(*f.data), f.type, *f.data, f.data->dims);
  };
  if (frames) {
    const FrameSeries& s = *frames;
    w.line(2, "<Grid Name=\"" + escapeXml(s.group.substr(1)) + "\" GridType=\"Collection\" CollectionType=\"Temporal\">");
    for (std::int64_t n = 0; n < s.frames; ++n) {
      w.line(3, "<Grid Name=\"frame " + number(n) + "\" GridType=\"Uniform\">");
      w.line(4, "<Time Value=\"" + number(double(n) * s.dt) + "\"/>");
      w.mesh(4, g, g.origin, g.shape);
      for (const Field& f : series) {
        w.frameAttribute(4, f.data->path.substr(groupPrefix.size()), f.type, *f.data, n);
      }
      staticAttributes(4);
      w.line(3, "</Grid>");
    }
    w.line(2, "</Grid>");
  } else if (!statics.empty()) {
    w.line(2, "<Grid Name=\"cells\" GridType=\"Uniform\">");
    w.mesh(3, g, g.origin, g.shape);
    staticAttributes(3);
    w.line(2, "</Grid>");
  }

  std::map<std::int64_t, std::vector<const DatasetInfo*>> mapsOfLayer;
  for (const LayerMap& m : layerMaps) {
    const auto found = std::find_if(datasets.begin(), datasets.end(), [&](const DatasetInfo& d) { return d.path == m.dataset; });
    const std::vector<hsize_t> plane{hsize_t(g.shape[1]), hsize_t(g.shape[0])};
    if (found == datasets.end() || found->dims != plane) {
      throw RunError("XDMF sidecar of " + h5Path + ": " + m.dataset + " is not a numeric [ny][nx] = [" +
                     number(plane[0]) + "][" + number(plane[1]) + "] dataset");
    }
    if (m.layer < 0 || m.layer >= g.shape[2]) {
      throw RunError("XDMF sidecar of " + h5Path + ": layer " + number(m.layer) + " of " + m.dataset +
                     " is outside the grid's " + number(g.shape[2]) + " layers");
    }
    mapsOfLayer[m.layer].push_back(&*found);
  }
  for (const auto& [layer, maps] : mapsOfLayer) {
    w.line(2, "<Grid Name=\"layer k = " + number(layer) + "\" GridType=\"Uniform\">");
    std::array<double, 3> origin = g.origin;
    origin[2] += double(layer) * g.spacing[2];
    w.mesh(3, g, origin, {g.shape[0], g.shape[1], 1});
    for (const DatasetInfo* d : maps) w.wholeAttribute(3, relativeName(*d), "Scalar", *d, {1, d->dims[0], d->dims[1]});
    w.line(2, "</Grid>");
  }
  w.line(1, "</Domain>");
  w.line(0, "</Xdmf>");
  return w.text();
}

bool writeSidecar(const std::string& h5Path, const CellGrid& grid, const std::vector<LayerMap>& layerMaps,
                  const std::optional<FrameSeries>& frames) {
  const std::string xml = sidecarXml(h5Path, grid, layerMaps, frames);
  const std::string path = sidecarPath(h5Path), tmp = path + ".tmp";
  if (xml.empty()) {
    std::error_code ec;
    std::filesystem::remove(path, ec);
    if (ec) throw RunError("cannot remove the outdated XDMF sidecar " + path + ": " + ec.message());
    return false;
  }
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << xml;
    out.flush();
    if (!out) throw RunError("cannot write the XDMF sidecar " + tmp);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw RunError("cannot rename " + tmp + " to " + path + ": " + ec.message());
  return true;
}

}  // namespace rcfd::xdmf
