#pragma once
/// \file WebPage.hpp
/// The web page of the job service (docs/web.md): static files served at GET / (index.html) and
/// GET /web/{name}, the only routes besides health answered without the token. They hold no data: the
/// page asks the authenticated API for everything with the token its user types in. Each answer
/// carries a Content-Security-Policy that allows scripts, styles and connections from this server only
/// (no inline script or style) and images from it or from blob: URLs (the job figures the page fetches
/// with the token), and X-Content-Type-Options: nosniff.

#include <string_view>

#include "HttpTypes.hpp"
#include "Target.hpp"

namespace rcfd::server {

/// The Content-Security-Policy of every file of the page.
inline constexpr std::string_view kWebContentSecurityPolicy =
    "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' blob:; connect-src 'self'; "
    "object-src 'none'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

/// Whether `path` (without the query) is one of the page's: "/" or "/web/NAME" (NAME without '/').
bool isWebPath(std::string_view path);

/// The answer to a GET of a page path: the file with its media type, or 404 for a name that is not one
/// of the page's files.
StringResponse webFile(const Target& target);

}  // namespace rcfd::server
