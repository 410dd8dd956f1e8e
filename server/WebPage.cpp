#include "WebPage.hpp"

#include "Problem.hpp"
#include "WebFiles.hpp"

namespace rcfd::server {

namespace {
constexpr std::string_view kPrefix = "/web/";
constexpr std::string_view kSourceDir = "server/web/";

std::string mediaType(std::string_view name) {
  const auto ends = [&](std::string_view ext) {
    return name.size() > ext.size() && name.substr(name.size() - ext.size()) == ext;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".js") || ends(".mjs")) return "text/javascript; charset=utf-8";
  if (ends(".svg")) return "image/svg+xml";
  if (ends(".png")) return "image/png";
  return "text/plain; charset=utf-8";
}
}  // namespace

bool isWebPath(std::string_view path) {
  if (path == "/") return true;
  if (path.size() <= kPrefix.size() || path.substr(0, kPrefix.size()) != kPrefix) return false;
  return path.find('/', kPrefix.size()) == std::string_view::npos;
}

StringResponse webFile(const Target& target) {
  // Names are looked up in the fixed list of embedded files, never decoded or joined into a path.
  const std::string name = target.path == "/" ? "index.html" : target.path.substr(kPrefix.size());
  const auto& files = webFiles();
  const auto it = files.find(std::string(kSourceDir) + name);
  if (it == files.end())
    return problem(http::status::not_found, "web-file-not-found", "Not found",
                   "the web page has no file \"" + name + "\"", target.path);
  auto res = textResponse(http::status::ok, std::string(it->second), mediaType(name));
  res.set("Content-Security-Policy", std::string(kWebContentSecurityPolicy));
  res.set("X-Content-Type-Options", "nosniff");
  res.set("Referrer-Policy", "no-referrer");
  res.set("Cross-Origin-Opener-Policy", "same-origin");
  // Revalidated on every load: a new server version brings its own page.
  res.set(http::field::cache_control, "no-cache");
  return res;
}

}  // namespace rcfd::server
