#pragma once
/// \file SectionFigure.hpp
/// The x-y cross-section of a scene's apparatus at the nozzle plane as an SVG figure: walls, inlet and
/// outlet, draft plates, the nozzle, the spray cone, the spray zone and the grid lines, with axes in
/// metres, a title and a legend. What `rcfd-solve geometry --svg` writes.

#include <string>

#include "core/Svg.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

/// Draws the section; throws rcfd::InputError if the scene's apparatus, grid or spray zone is invalid.
SvgDocument drawSection(const Scene& scene);

/// drawSection() written to `path`; throws rcfd::RunError if the file cannot be written.
void writeSectionSvg(const Scene& scene, const std::string& path);

}  // namespace rcfd
