#pragma once
/// \file WebFiles.hpp
/// The files of the web page (server/web/), compiled into the server by cmake/EmbedFiles.cmake like the
/// schemas: keyed by their path in the repository ("server/web/app.js").

#include <map>
#include <string>
#include <string_view>

namespace rcfd::server {

const std::map<std::string, std::string_view>& webFiles();

}  // namespace rcfd::server
