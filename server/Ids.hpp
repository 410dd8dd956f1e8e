#pragma once
/// \file Ids.hpp
/// Unguessable resource ids, opaque page tokens and request body hashes.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace rcfd::server {

/// 128 random bits from the OS entropy source as 32 lowercase hex digits.
std::string newId();
/// True if `s` looks like an id from newId() (32 lowercase hex digits).
bool isId(std::string_view s);
/// FNV-1a 64-bit hash as 16 hex digits (compares request bodies for Idempotency-Key; not a MAC).
std::string bodyHash(std::string_view body);
/// base64url without padding, for opaque page tokens.
std::string base64UrlEncode(std::string_view data);
std::optional<std::string> base64UrlDecode(std::string_view text);

}  // namespace rcfd::server
