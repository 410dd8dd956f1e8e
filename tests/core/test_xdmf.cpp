// The XDMF sidecar writer: the XML parses, and every array it declares matches the HDF5 dataset it
// points to (name, dimensions, type); frames carry their times, layer maps their layer.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "../fields/FieldTestUtil.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "core/Xdmf.hpp"

namespace {

using rcfd::test::tempPath;

/// A parsed XML element: a small reader for the sidecars, which use elements, attributes in double
/// quotes, text and the five predefined entities only. Throws std::runtime_error on anything that is not
/// well-formed (unbalanced tags, a tag left open, an unquoted attribute, an unknown entity).
struct Element {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::vector<Element> children;
  std::string text;

  std::vector<const Element*> all(const std::string& tag) const {
    std::vector<const Element*> out;
    for (const Element& c : children)
      if (c.name == tag) out.push_back(&c);
    return out;
  }
  const Element& only(const std::string& tag) const {
    const auto found = all(tag);
    if (found.size() != 1) throw std::runtime_error("expected one <" + tag + "> in <" + name + ">");
    return *found.front();
  }
};

std::string unescape(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '&') {
      out += s[i];
      continue;
    }
    const std::size_t end = s.find(';', i);
    if (end == std::string::npos) throw std::runtime_error("unterminated entity");
    const std::string e = s.substr(i + 1, end - i - 1);
    static const std::map<std::string, char> known{{"amp", '&'}, {"lt", '<'}, {"gt", '>'}, {"quot", '"'}, {"apos", '\''}};
    if (!known.count(e)) throw std::runtime_error("unknown entity &" + e + ";");
    out += known.at(e);
    i = end;
  }
  return out;
}

Element parseXml(const std::string& xml) {
  Element document;
  std::vector<Element*> open{&document};
  std::size_t pos = 0;
  while (pos < xml.size()) {
    const std::size_t lt = xml.find('<', pos);
    const std::string text = xml.substr(pos, lt == std::string::npos ? std::string::npos : lt - pos);
    if (text.find('>') != std::string::npos) throw std::runtime_error("stray '>' in text");
    open.back()->text += unescape(text);
    if (lt == std::string::npos) break;
    const std::size_t gt = xml.find('>', lt);
    if (gt == std::string::npos) throw std::runtime_error("unterminated tag");
    std::string tag = xml.substr(lt + 1, gt - lt - 1);
    pos = gt + 1;
    if (tag.front() == '?') {
      if (tag.back() != '?' || open.size() != 1) throw std::runtime_error("misplaced declaration");
      continue;
    }
    if (tag.front() == '/') {
      if (open.size() < 2 || open.back()->name != tag.substr(1)) throw std::runtime_error("mismatched </" + tag.substr(1) + ">");
      open.pop_back();
      continue;
    }
    const bool selfClosing = tag.back() == '/';
    if (selfClosing) tag.pop_back();
    Element e;
    std::istringstream in(tag);
    in >> e.name;
    std::size_t at = e.name.size();
    while (true) {
      while (at < tag.size() && std::isspace(static_cast<unsigned char>(tag[at]))) ++at;
      if (at >= tag.size()) break;
      const std::size_t eq = tag.find('=', at);
      if (eq == std::string::npos || eq + 1 >= tag.size() || tag[eq + 1] != '"') throw std::runtime_error("bad attribute in <" + tag + ">");
      const std::size_t close = tag.find('"', eq + 2);
      if (close == std::string::npos) throw std::runtime_error("unterminated attribute in <" + tag + ">");
      const std::string key = tag.substr(at, eq - at);
      if (e.attributes.count(key)) throw std::runtime_error("duplicate attribute " + key);
      e.attributes[key] = unescape(tag.substr(eq + 2, close - eq - 2));
      at = close + 1;
    }
    open.back()->children.push_back(std::move(e));
    if (!selfClosing) open.push_back(&open.back()->children.back());
  }
  if (open.size() != 1) throw std::runtime_error("<" + open.back()->name + "> is not closed");
  if (document.children.size() != 1) throw std::runtime_error("not exactly one root element");
  return document.children.front();
}

std::vector<std::int64_t> numbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::int64_t> out;
  for (std::int64_t v; in >> v;) out.push_back(v);
  return out;
}

std::vector<double> reals(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> out;
  for (double v; in >> v;) out.push_back(v);
  return out;
}

/// The HDF5 file, dataset and (for a frame) the start:stride:count:dataspace of a DataItem.
struct HeavyReference {
  std::string file, dataset;
  std::vector<std::vector<std::int64_t>> selection;
};

HeavyReference heavyReference(const Element& item) {
  HeavyReference r;
  std::string text = item.text;
  text.erase(0, text.find_first_not_of(" \n"));
  text.erase(text.find_last_not_of(" \n") + 1);
  const std::size_t bar = text.find('|');
  const std::string location = text.substr(0, bar);
  const std::size_t colon = location.find(':');
  r.file = location.substr(0, colon);
  r.dataset = location.substr(colon + 1);
  if (bar != std::string::npos) {
    std::istringstream parts(text.substr(bar + 1));
    for (std::string part; std::getline(parts, part, ':');) r.selection.push_back(numbers(part));
  }
  return r;
}

/// The grid of the tests: 4 x 3 x 2 cells, every spacing and origin component different.
rcfd::xdmf::CellGrid testGrid() {
  rcfd::xdmf::CellGrid g;
  g.origin = {-0.02, 0.5, 1.25};
  g.spacing = {0.01, 0.02, 0.04};
  g.shape = {4, 3, 2};
  return g;
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Checks every grid's mesh against `g` (with `layers` cells along z from layer `k0`) and returns its
/// attributes by name.
std::map<std::string, const Element*> checkGrid(const Element& grid, const rcfd::xdmf::CellGrid& g, std::int64_t k0 = 0,
                                                std::int64_t layers = -1) {
  if (layers < 0) layers = g.shape[2];
  const Element& topology = grid.only("Topology");
  EXPECT_EQ(topology.attributes.at("TopologyType"), "3DCoRectMesh");
  // Points, slowest axis first: z y x.
  EXPECT_EQ(numbers(topology.attributes.at("Dimensions")),
            (std::vector<std::int64_t>{layers + 1, g.shape[1] + 1, g.shape[0] + 1}));
  const Element& geometry = grid.only("Geometry");
  EXPECT_EQ(geometry.attributes.at("GeometryType"), "ORIGIN_DXDYDZ");
  const auto items = geometry.all("DataItem");
  EXPECT_EQ(items.size(), 2u);
  const auto origin = reals(items.at(0)->text), spacing = reals(items.at(1)->text);
  EXPECT_EQ(origin, (std::vector<double>{g.origin[2] + double(k0) * g.spacing[2], g.origin[1], g.origin[0]}));
  EXPECT_EQ(spacing, (std::vector<double>{g.spacing[2], g.spacing[1], g.spacing[0]}));
  std::map<std::string, const Element*> attributes;
  for (const Element* a : grid.all("Attribute")) {
    EXPECT_EQ(a->attributes.at("Center"), "Cell");
    EXPECT_FALSE(attributes.count(a->attributes.at("Name"))) << a->attributes.at("Name");
    attributes[a->attributes.at("Name")] = a;
  }
  return attributes;
}

/// The attribute's DataItem points at `dataset` of the file beside the sidecar, with that dataset's
/// shape (`dims`; for a frame the dataset's dims without the first; for a layer map, read as one layer,
/// the dataset's dims after a 1), type and precision.
void expectPointsAt(const Element& attribute, const std::string& h5Path, const std::string& dataset,
                    const std::vector<std::int64_t>& dims, const std::string& numberType, const std::string& precision,
                    bool layerMap = false) {
  const Element& item = attribute.only("DataItem");
  const HeavyReference ref = heavyReference(item);
  EXPECT_EQ(ref.file, std::filesystem::path(h5Path).filename().string());
  EXPECT_EQ(ref.dataset, dataset);
  EXPECT_EQ(item.attributes.at("Format"), "HDF");
  EXPECT_EQ(item.attributes.at("NumberType"), numberType);
  EXPECT_EQ(item.attributes.at("Precision"), precision);
  EXPECT_EQ(numbers(item.attributes.at("Dimensions")), dims);
  rcfd::h5::File f(h5Path, rcfd::h5::File::Mode::ReadOnly);
  ASSERT_TRUE(f.exists(dataset)) << dataset;
  const auto shape = f.shape(dataset);
  std::vector<std::int64_t> stored(shape.begin(), shape.end());
  if (layerMap) {
    EXPECT_EQ(std::vector<std::int64_t>{1}, std::vector<std::int64_t>(dims.begin(), dims.begin() + 1));
    EXPECT_EQ(stored, std::vector<std::int64_t>(dims.begin() + 1, dims.end())) << dataset;
  } else if (ref.selection.empty()) {
    EXPECT_EQ(stored, dims) << dataset;
  } else {
    EXPECT_EQ(std::vector<std::int64_t>(stored.begin() + 1, stored.end()), dims) << dataset;
    EXPECT_EQ(ref.selection.at(3), stored) << dataset;  // the dataspace
  }
}

/// A result file as the jobs write one: cell fields among datasets that are none.
std::string writeResultFile(const rcfd::xdmf::CellGrid& g) {
  const std::string path = tempPath("result.h5");
  const hsize_t nx = hsize_t(g.shape[0]), ny = hsize_t(g.shape[1]), nz = hsize_t(g.shape[2]);
  rcfd::h5::File f(path, rcfd::h5::File::Mode::Create);
  f.writeString("/scene", "{}");
  f.write("/field_average/alpha_p_tracers", std::vector<float>(nx * ny * nz, 0.25f), {nz, ny, nx});
  f.write("/deposition_maps/rate_density", std::vector<double>(nx * ny * nz, 2.0), {nz, ny, nx});
  f.write("/velocity/u_mean", std::vector<double>(nx * ny * nz * 3, 1.0), {nz, ny, nx, 3});
  f.write("/cells/owner", std::vector<std::int64_t>(nx * ny * nz, 7), {nz, ny, nx});
  f.write("/deposition_maps/midplane_z", std::vector<double>(nx * ny, 3.0), {ny, nx});
  f.write("/coverage/per_tracer", std::vector<double>(nx * ny * nz, 0.5));  // 1-D: no cell field
  f.write("/transposed", std::vector<double>(nx * ny * nz, 0.0), {nx, ny, nz});  // [nx][ny][nz]: not rcfd's order
  f.write("/ensemble/members/01/deposition_maps/rate_density", std::vector<double>(nx * ny * nz, 4.0), {nz, ny, nx});
  f.hardLink("/deposition_maps/rate_density", "/ensemble/members/00/deposition_maps/rate_density");
  return path;
}

}  // namespace

TEST(Xdmf, SidecarPathReplacesTheExtension) {
  EXPECT_EQ(rcfd::xdmf::sidecarPath("/a/b/database.h5"), "/a/b/database.xmf");
  EXPECT_EQ(rcfd::xdmf::sidecarPath("result.h5"), "result.xmf");
}

TEST(Xdmf, ResultSidecarDeclaresEveryCellFieldOnceWithItsShapeAndType) {
  const auto g = testGrid();
  const std::string h5 = writeResultFile(g);
  EXPECT_TRUE(rcfd::xdmf::writeSidecar(h5, g));
  const std::string xmfPath = rcfd::xdmf::sidecarPath(h5);
  ASSERT_TRUE(std::filesystem::exists(xmfPath));
  EXPECT_FALSE(std::filesystem::exists(xmfPath + ".tmp"));
  const Element root = parseXml(readText(xmfPath));
  EXPECT_EQ(root.name, "Xdmf");
  EXPECT_EQ(root.attributes.at("Version"), "3.0");
  const Element& domain = root.only("Domain");
  const auto grids = domain.all("Grid");
  ASSERT_EQ(grids.size(), 1u);
  EXPECT_EQ(grids[0]->attributes.at("GridType"), "Uniform");
  const auto attributes = checkGrid(*grids[0], g);

  std::vector<std::string> names;
  for (const auto& [name, element] : attributes) names.push_back(name);
  // The shared dataset once, under the root's name; member 01's own copy under its path.
  EXPECT_EQ(names, (std::vector<std::string>{"cells/owner", "deposition_maps/rate_density",
                                             "ensemble/members/01/deposition_maps/rate_density",
                                             "field_average/alpha_p_tracers", "velocity/u_mean"}));
  const std::vector<std::int64_t> cells{2, 3, 4};
  expectPointsAt(*attributes.at("field_average/alpha_p_tracers"), h5, "/field_average/alpha_p_tracers", cells, "Float", "4");
  expectPointsAt(*attributes.at("deposition_maps/rate_density"), h5, "/deposition_maps/rate_density", cells, "Float", "8");
  expectPointsAt(*attributes.at("cells/owner"), h5, "/cells/owner", cells, "Int", "8");
  expectPointsAt(*attributes.at("velocity/u_mean"), h5, "/velocity/u_mean", {2, 3, 4, 3}, "Float", "8");
  EXPECT_EQ(attributes.at("velocity/u_mean")->attributes.at("AttributeType"), "Vector");
  EXPECT_EQ(attributes.at("deposition_maps/rate_density")->attributes.at("AttributeType"), "Scalar");
}

TEST(Xdmf, DatabaseSidecarHasOneGridPerFrameWithItsTimeAndSlab) {
  const auto g = testGrid();
  const std::string h5 = tempPath("database.h5");
  const hsize_t nx = 4, ny = 3, nz = 2, cells = nx * ny * nz;
  {
    rcfd::h5::File f(h5, rcfd::h5::File::Mode::Create);
    f.write("/grid/fluid_fraction", std::vector<float>(cells, 1.0f), {nz, ny, nx});
    // One frame more than complete: the series shows the complete ones only.
    f.write("/frames/alpha_p", std::vector<float>(4 * cells, 0.1f), {4, nz, ny, nx});
    f.write("/frames/u_p", std::vector<float>(4 * cells * 3, 0.1f), {4, nz, ny, nx, 3});
    f.write("/frames/u_g", std::vector<float>(3 * cells * 3, 0.1f), {3, nz, ny, nx, 3});
    f.write("/frames/too_short", std::vector<float>(2 * cells, 0.1f), {2, nz, ny, nx});
    f.write("/recurrence/matrix", std::vector<float>(16, 0.0f), {4, 4});
  }
  const double dt = 0.005;
  rcfd::xdmf::writeSidecar(h5, g, {}, rcfd::xdmf::FrameSeries{"/frames", 3, dt});
  const Element root = parseXml(readText(rcfd::xdmf::sidecarPath(h5)));
  const auto top = root.only("Domain").all("Grid");
  ASSERT_EQ(top.size(), 1u);
  EXPECT_EQ(top[0]->attributes.at("GridType"), "Collection");
  EXPECT_EQ(top[0]->attributes.at("CollectionType"), "Temporal");
  const auto frames = top[0]->all("Grid");
  ASSERT_EQ(frames.size(), 3u);
  for (std::size_t n = 0; n < frames.size(); ++n) {
    SCOPED_TRACE("frame " + std::to_string(n));
    EXPECT_DOUBLE_EQ(std::stod(frames[n]->only("Time").attributes.at("Value")), double(n) * dt);
    const auto attributes = checkGrid(*frames[n], g);
    std::vector<std::string> names;
    for (const auto& [name, element] : attributes) names.push_back(name);
    EXPECT_EQ(names, (std::vector<std::string>{"alpha_p", "grid/fluid_fraction", "u_g", "u_p"}));
    expectPointsAt(*attributes.at("alpha_p"), h5, "/frames/alpha_p", {2, 3, 4}, "Float", "4");
    expectPointsAt(*attributes.at("u_p"), h5, "/frames/u_p", {2, 3, 4, 3}, "Float", "4");
    expectPointsAt(*attributes.at("u_g"), h5, "/frames/u_g", {2, 3, 4, 3}, "Float", "4");
    expectPointsAt(*attributes.at("grid/fluid_fraction"), h5, "/grid/fluid_fraction", {2, 3, 4}, "Float", "4");
    const auto slab = heavyReference(attributes.at("u_p")->only("DataItem"));
    ASSERT_EQ(slab.selection.size(), 4u);
    EXPECT_EQ(slab.selection[0], (std::vector<std::int64_t>{std::int64_t(n), 0, 0, 0, 0}));  // start
    EXPECT_EQ(slab.selection[1], (std::vector<std::int64_t>{1, 1, 1, 1, 1}));                 // stride
    EXPECT_EQ(slab.selection[2], (std::vector<std::int64_t>{1, 2, 3, 4, 3}));                 // count
  }
}

TEST(Xdmf, LayerMapsSitOnTheirLayerOneCellThick) {
  const auto g = testGrid();
  const std::string h5 = tempPath("calibration.h5");
  {
    rcfd::h5::File f(h5, rcfd::h5::File::Mode::Create);
    f.write("/calibration/recurrence/alpha_p_midplane", std::vector<float>(12, 0.2f), {3, 4});
    f.write("/calibration/runs/d0_0/field_average/alpha_p_midplane", std::vector<float>(12, 0.3f), {3, 4});
    f.write("/calibration/d0", std::vector<double>{1e-4});
  }
  rcfd::xdmf::writeSidecar(h5, g,
                           {{"/calibration/recurrence/alpha_p_midplane", 1},
                            {"/calibration/runs/d0_0/field_average/alpha_p_midplane", 1}});
  const Element root = parseXml(readText(rcfd::xdmf::sidecarPath(h5)));
  const auto grids = root.only("Domain").all("Grid");
  ASSERT_EQ(grids.size(), 1u);  // no 3-D field, one layer
  const auto attributes = checkGrid(*grids[0], g, 1, 1);
  ASSERT_EQ(attributes.size(), 2u);
  for (const auto& [name, attribute] : attributes) {
    expectPointsAt(*attribute, h5, "/" + name, {1, 3, 4}, "Float", "4", true);
  }
}

TEST(Xdmf, RefusesALayerMapOfTheWrongShapeOrLayer) {
  const auto g = testGrid();
  const std::string h5 = writeResultFile(g);
  EXPECT_THROW(rcfd::xdmf::sidecarXml(h5, g, {{"/deposition_maps/rate_density", 0}}), rcfd::RunError);
  EXPECT_THROW(rcfd::xdmf::sidecarXml(h5, g, {{"/no/such/map", 0}}), rcfd::RunError);
  EXPECT_THROW(rcfd::xdmf::sidecarXml(h5, g, {{"/deposition_maps/midplane_z", 2}}), rcfd::RunError);
  EXPECT_NO_THROW(rcfd::xdmf::sidecarXml(h5, g, {{"/deposition_maps/midplane_z", 1}}));
}

TEST(Xdmf, NamesWithXmlCharactersAreEscaped) {
  const auto g = testGrid();
  const std::string h5 = tempPath("a&b.h5");
  {
    rcfd::h5::File f(h5, rcfd::h5::File::Mode::Create);
    f.write("/fields/\"quoted\" <x>", std::vector<double>(24, 1.0), {2, 3, 4});
  }
  const Element root = parseXml(rcfd::xdmf::sidecarXml(h5, g));
  const auto attributes = checkGrid(root.only("Domain").only("Grid"), g);
  ASSERT_EQ(attributes.size(), 1u);
  EXPECT_EQ(attributes.begin()->first, "fields/\"quoted\" <x>");
  EXPECT_EQ(heavyReference(attributes.begin()->second->only("DataItem")).file,
            std::filesystem::path(h5).filename().string());
}

TEST(Xdmf, AFileWithoutCellFieldsGetsNoSidecarAndLosesAnOldOne) {
  const auto g = testGrid();
  const std::string h5 = tempPath("result.h5");
  {
    rcfd::h5::File f(h5, rcfd::h5::File::Mode::Create);
    f.write("/coverage/per_tracer", std::vector<double>(24, 0.5));
    f.write("/probes/alpha_p_tracers", std::vector<double>(12, 0.1), {3, 4});  // [ny][nx]-shaped, but no map
  }
  std::ofstream(rcfd::xdmf::sidecarPath(h5)) << "<Xdmf/>";
  EXPECT_EQ(rcfd::xdmf::sidecarXml(h5, g), "");
  EXPECT_FALSE(rcfd::xdmf::writeSidecar(h5, g));
  EXPECT_FALSE(std::filesystem::exists(rcfd::xdmf::sidecarPath(h5)));
}

TEST(Xdmf, WriteFailuresAreRunErrorsNamingTheFile) {
  const auto g = testGrid();
  EXPECT_THROW(rcfd::xdmf::writeSidecar(tempPath("missing.h5"), g), rcfd::RunError);
  const std::string h5 = writeResultFile(g);
  std::filesystem::create_directories(rcfd::xdmf::sidecarPath(h5) + ".tmp");  // the temporary cannot be created
  try {
    rcfd::xdmf::writeSidecar(h5, g);
    FAIL() << "no error";
  } catch (const rcfd::RunError& e) {
    EXPECT_NE(std::string(e.what()).find(rcfd::xdmf::sidecarPath(h5)), std::string::npos) << e.what();
  }
}

TEST(Xdmf, TheTestReaderRejectsMalformedXml) {
  EXPECT_THROW(parseXml("<a><b></a></b>"), std::runtime_error);
  EXPECT_THROW(parseXml("<a x=1/>"), std::runtime_error);
  EXPECT_THROW(parseXml("<a>"), std::runtime_error);
  EXPECT_THROW(parseXml("<a>&nbsp;</a>"), std::runtime_error);
  EXPECT_NO_THROW(parseXml("<?xml version=\"1.0\"?>\n<a x=\"1\"><b/>t</a>\n"));
}
