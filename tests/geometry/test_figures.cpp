// The section SVG and the open-fraction VTK written from scenes built in C++. The two ProCell figures
// are also written to build/geometry-figures/ (copied to docs/ by hand: docs/geometry.md).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "GeometryFixtures.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/GridVtk.hpp"
#include "geometry/SectionFigure.hpp"

namespace rcfd {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

Scene paperScene(bool plates) {
  Scene s;
  s.name = plates ? "procell-draft-plates" : "procell-unstabilised";
  s.apparatus = test::procellSpec(plates);
  s.grid.cell_size = Eigen::Vector3d::Constant(0.005);
  s.spray.nozzle_position = Eigen::Vector3d(0.0, 0.0, 0.1);
  s.spray.nozzle_diameter = 0.004;
  s.spray.cone_half_angle_deg = 17.0;
  s.spray.spray_zone.apex = Eigen::Vector3d(0.0, 0.0, 0.1);
  s.spray.spray_zone.half_angle_deg = 17.0;
  s.spray.spray_zone.y_min = 0.02;
  s.spray.spray_zone.y_max = 0.1;
  return s;
}

std::string outDir() {
  const std::string dir = std::string(RCFD_BINARY_DIR) + "/geometry-figures";
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(Figures, SectionSvgDrawsTheChamber) {
  for (bool plates : {false, true}) {
    const Scene scene = paperScene(plates);
    const std::string path = outDir() + "/" + scene.name + ".svg";
    writeSectionSvg(scene, path);
    const std::string svg = readFile(path);
    ASSERT_FALSE(svg.empty());
    EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    // XML-ish: every text element is closed, every other element self-closes.
    EXPECT_EQ(count(svg, "<text"), count(svg, "</text>"));
    EXPECT_EQ(count(svg, "<line") + count(svg, "<polygon") + count(svg, "<rect") + count(svg, "<circle") +
                  count(svg, "<polyline"),
              count(svg, "/>"));
    // The outline polygon with the V-to-vertical corner at its pixel position.
    const SvgDocument doc = drawSection(scene);
    char corner[64];
    std::snprintf(corner, sizeof corner, "%.2f,%.2f", doc.px(0.125), doc.py(test::procellYv()));
    EXPECT_NE(svg.find(corner), std::string::npos) << corner;
    EXPECT_NE(svg.find("<polygon"), std::string::npos);
    EXPECT_NE(svg.find("gas inlet"), std::string::npos);
    EXPECT_NE(svg.find("outlet"), std::string::npos);
    EXPECT_NE(svg.find("spray zone"), std::string::npos);
    EXPECT_NE(svg.find("stroke-opacity"), std::string::npos);  // translucent cone rays
    EXPECT_EQ(svg.find("draft plate") != std::string::npos, plates);
    // Grid lines: 51 vertical and 121 horizontal ones in light grey.
    EXPECT_GE(count(svg, "stroke=\"#d9d9d9\""), 51u + 121u);
  }
}

TEST(Figures, SectionSvgRefusesAnInvalidScene) {
  Scene scene = paperScene(true);
  scene.apparatus.draft_plates->elevation = 0.01;
  EXPECT_THROW(drawSection(scene), InputError);
  EXPECT_THROW(writeSectionSvg(paperScene(false), "/nonexistent-dir/x.svg"), RunError);
}

TEST(Figures, OpenFractionVtk) {
  const Apparatus app(test::procellSpec(true));
  GridSpec spec;
  spec.cell_size = Eigen::Vector3d::Constant(0.005);
  const CartesianGrid grid = makeGrid(app, spec);
  const auto f = openFractions(app, grid);
  const std::string path = outDir() + "/procell-draft-plates.vtk";
  writeOpenFractionVtk(app, grid, f, path);
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "# vtk DataFile Version 3.0");
  std::getline(in, line);
  std::getline(in, line);
  EXPECT_EQ(line, "ASCII");
  std::getline(in, line);
  EXPECT_EQ(line, "DATASET STRUCTURED_POINTS");
  std::getline(in, line);
  EXPECT_EQ(line, "DIMENSIONS 51 121 41");
  std::getline(in, line);
  EXPECT_EQ(line.rfind("ORIGIN -0.125 0 0", 0), 0u) << line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("SPACING 0.005", 0), 0u) << line;
  std::getline(in, line);
  EXPECT_EQ(line, "CELL_DATA 240000");
  std::getline(in, line);
  EXPECT_EQ(line, "SCALARS open_fraction double 1");
  std::getline(in, line);
  EXPECT_EQ(line, "LOOKUP_TABLE default");
  std::vector<double> values;
  double v;
  while (in >> v) values.push_back(v);
  ASSERT_EQ(values.size(), 240000u);
  double open = 0.0;
  for (std::size_t c = 0; c < values.size(); ++c) {
    EXPECT_NEAR(values[c], f[c], 1e-8);
    open += values[c] * grid.cellVolume();
  }
  EXPECT_NEAR(open / app.openVolume(), 1.0, 1e-7);
  EXPECT_THROW(writeOpenFractionVtk(app, grid, std::vector<double>(3), path), std::invalid_argument);
}

}  // namespace
}  // namespace rcfd
