// rcfd-solve geometry SCENE.json --svg OUT.svg [--vtk OUT.vtk]: draws the apparatus's cross-section and
// writes the grid's open fractions; prints the volumes and the grid to stdout.

#include <cstdio>
#include <memory>

#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/GridVtk.hpp"
#include "geometry/SectionFigure.hpp"
#include "scene/SceneLoader.hpp"

namespace {
const bool registered = rcfd::cli::addCommand(
    "geometry", "draw a scene's apparatus section (SVG) and write the grid's open fractions (VTK)",
    [](CLI::App& app) {
      auto scenePath = std::make_shared<std::string>();
      auto svgPath = std::make_shared<std::string>();
      auto vtkPath = std::make_shared<std::string>();
      app.add_option("SCENE", *scenePath, "scene JSON file")->required();
      app.add_option("--svg", *svgPath, "write the x-y section at the nozzle plane here")->required();
      app.add_option("--vtk", *vtkPath, "write the open fraction per cell here (legacy VTK)");
      return [scenePath, svgPath, vtkPath] {
        const rcfd::Scene scene = rcfd::loadSceneFile(*scenePath);
        const rcfd::Apparatus apparatus(scene.apparatus);
        const rcfd::CartesianGrid grid = rcfd::makeGrid(apparatus, scene.grid);
        rcfd::writeSectionSvg(scene, *svgPath);
        const std::vector<double> fractions = rcfd::openFractions(apparatus, grid);
        double open = 0.0;
        std::int64_t openCells = 0;
        for (double f : fractions) {
          open += f * grid.cellVolume();
          openCells += f > 0.0;
        }
        if (!vtkPath->empty()) rcfd::writeOpenFractionVtk(apparatus, grid, fractions, *vtkPath);
        std::printf("section area      %.6e m2\n", apparatus.sectionArea());
        std::printf("open volume       %.6e m3 (analytic)\n", apparatus.openVolume());
        std::printf("grid open volume  %.6e m3 (sum of open fractions)\n", open);
        std::printf("grid              %d x %d x %d cells of %.4g x %.4g x %.4g m, %lld (partly) open\n",
                    grid.shape[0], grid.shape[1], grid.shape[2], grid.spacing.x(), grid.spacing.y(),
                    grid.spacing.z(), static_cast<long long>(openCells));
        std::printf("svg               %s\n", svgPath->c_str());
        if (!vtkPath->empty()) std::printf("vtk               %s\n", vtkPath->c_str());
        return rcfd::exit_code::success;
      };
    });
}  // namespace
