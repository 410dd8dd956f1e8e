#pragma once
/// \file SceneJson.hpp
/// Conversion between a schema-valid scene document and the typed Scene, in both directions, with
/// the schema's key names. Absent keys take the C++ defaults of Scene.hpp.

#include <nlohmann/json.hpp>

#include "scene/Scene.hpp"

namespace rcfd {

/// JSON (already valid against schemas/scene.schema.json) -> Scene. source_json is left empty.
Scene sceneFromJson(const nlohmann::json& document);

/// Scene -> JSON with every value spelled out (defaults included); sceneFromJson(sceneToJson(s))
/// reproduces s. `grid.cell_size` is always written as [dx, dy, dz].
nlohmann::json sceneToJson(const Scene& scene);

}  // namespace rcfd
