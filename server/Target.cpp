#include "Target.hpp"

namespace rcfd::server {

namespace {
std::optional<std::string> percentDecode(std::string_view s, bool plusIsSpace) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%') {
      if (i + 2 >= s.size()) return std::nullopt;
      auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
      };
      const int hi = hex(s[i + 1]), lo = hex(s[i + 2]);
      if (hi < 0 || lo < 0) return std::nullopt;
      out.push_back(static_cast<char>(hi * 16 + lo));
      i += 2;
    } else if (plusIsSpace && s[i] == '+') {
      out.push_back(' ');
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}
}  // namespace

std::optional<Target> parseTarget(std::string_view target) {
  if (target.empty() || target.front() != '/') return std::nullopt;
  Target t;
  const auto q = target.find('?');
  t.path = std::string(target.substr(0, q));
  std::size_t start = 1;
  while (start <= t.path.size()) {
    const auto end = std::min(t.path.find('/', start), t.path.size());
    // Path segments are kept raw: names are matched against fixed lists, never decoded into paths.
    std::string segment = t.path.substr(start, end - start);
    if (segment == "." || segment == "..") t.dotSegment = true;
    if (!segment.empty()) t.segments.push_back(std::move(segment));
    start = end + 1;
  }
  if (q != std::string_view::npos) {
    std::string_view query = target.substr(q + 1);
    while (!query.empty()) {
      const auto amp = query.find('&');
      const std::string_view pair = query.substr(0, amp);
      const auto eq = pair.find('=');
      auto key = percentDecode(pair.substr(0, eq), true);
      auto value = percentDecode(eq == std::string_view::npos ? "" : pair.substr(eq + 1), true);
      if (!key || !value) return std::nullopt;
      if (!key->empty()) t.query[*key] = *value;
      if (amp == std::string_view::npos) break;
      query.remove_prefix(amp + 1);
    }
  }
  return t;
}

std::string instancePath(std::string_view target) {
  constexpr std::size_t kMaxLength = 200;
  const std::string_view path = target.substr(0, target.find('?'));
  std::string out;
  for (const char c : path) {
    if (out.size() >= kMaxLength) break;
    const auto byte = static_cast<unsigned char>(c);
    if (byte > 0x20 && byte < 0x7f) {
      out.push_back(c);
    } else {
      static const char* const hex = "0123456789ABCDEF";
      out += {'%', hex[byte >> 4], hex[byte & 15]};
    }
  }
  return out.empty() ? "*" : out;
}

}  // namespace rcfd::server
