#pragma once
/// \file ExamplesApi.hpp
/// GET /v1/examples and GET /v1/examples/{name}: the example scenes of the repository (examples/*.json),
/// compiled into the binaries with the schemas, so a client (the web page) can start from one without a
/// copy of the repository.

#include "HttpTypes.hpp"
#include "Target.hpp"

namespace rcfd::server {

/// {"examples": [{"name", "description"}]}: every embedded example scene by name (its file name
/// without .json), in name order.
StringResponse listExamples();

/// The scene `name` as its file holds it (application/json), or 404 naming the ones there are.
StringResponse getExample(const std::string& name, const Target& target);

}  // namespace rcfd::server
