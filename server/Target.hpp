#pragma once
/// \file Target.hpp
/// A request target split into path segments and decoded query parameters.

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rcfd::server {

struct Target {
  std::string path;                          ///< as received, without the query
  std::vector<std::string> segments;         ///< path split at '/', empty segments dropped
  std::map<std::string, std::string> query;  ///< percent-decoded; the last of repeated keys wins
  bool dotSegment = false;                   ///< a "." or ".." segment (never valid here)
};

/// Parses an origin-form target ("/v1/jobs?state=QUEUED"); nullopt if it is malformed.
std::optional<Target> parseTarget(std::string_view target);

/// The `instance` of a problem about a request with this target: its path without the query, bytes
/// outside printable ASCII percent-encoded, at most 200 characters; "*" (the asterisk form of
/// RFC 9112: the server as a whole) when the request line held no target.
std::string instancePath(std::string_view target);

}  // namespace rcfd::server
