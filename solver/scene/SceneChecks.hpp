#pragma once
/// \file SceneChecks.hpp
/// Rules for scenes that a JSON Schema cannot express: relations between values (y_min < y_max of
/// the spray zone, min <= max sequence fraction), points inside the apparatus's bounding box, cells
/// smaller than the apparatus, draft plates clear of the walls, finite numbers.

#include <nlohmann/json.hpp>
#include <vector>

#include "core/Errors.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

/// Every violation of the semantic rules by a schema-valid scene (`document` is its JSON, used to
/// tell given values from defaults); pointers are relative to the scene document.
std::vector<Violation> checkSceneSemantics(const Scene& scene, const nlohmann::json& document);

/// Limits checked before the schema, for scenes and job files alike: nesting deeper than
/// kMaxDocumentDepth and arrays longer than kMaxArrayItems (the recursive and quadratic parts of any
/// validator would otherwise let one request exhaust the stack or the CPU), doubles that are not
/// finite and integers beyond int64 (valijson reads those as negative).
inline constexpr int kMaxDocumentDepth = 32;
inline constexpr std::size_t kMaxArrayItems = 100000;
std::vector<Violation> documentLimitViolations(const nlohmann::json& document);

/// Rules a scene must meet to be simulated by the CFD-DEM of a database job (pointers into the scene):
/// the bed fits the chamber, the DEM time step is within dem.max_rayleigh_fraction of the Rayleigh time,
/// and the frames and reference samples fall on whole DEM steps (DatabaseSchedule).
std::vector<Violation> checkDatabaseScene(const Scene& scene);

/// Lower and upper corner of the apparatus's bounding box (docs/contracts.md, "Coordinates") [m].
void apparatusBounds(const ApparatusSpec& apparatus, Vec3& lower, Vec3& upper);

}  // namespace rcfd
