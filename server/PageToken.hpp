#pragma once
/// \file PageToken.hpp
/// Page tokens of a listing, signed so that a client can pass back only what the server issued: the
/// token is base64url(payload) "." base64url(HMAC-SHA256(key, payload)). The key is the server's own,
/// kept in the data directory (pageTokenKey), so tokens survive a restart of the same server.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace rcfd::server {

/// The signing key in `dataDir/page-token.key`: 32 random bytes, created owner-only at first use.
std::string pageTokenKey(const std::filesystem::path& dataDir);

std::string signPageToken(const nlohmann::json& payload, const std::string& key);

/// The payload of a token this key signed; nullopt for anything else (forged, altered, truncated).
std::optional<nlohmann::json> verifyPageToken(const std::string& token, const std::string& key);

}  // namespace rcfd::server
