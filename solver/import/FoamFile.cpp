#include "import/FoamFile.hpp"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/Errors.hpp"

namespace rcfd::openfoam {
namespace {

static_assert(std::endian::native == std::endian::little,
              "binary OpenFOAM files are read as little-endian values in place");

bool isPunctuation(char c) {
  return c == '(' || c == ')' || c == '{' || c == '}' || c == '[' || c == ']' || c == ';';
}
bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

std::string readPlain(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "", std::string("cannot read the file: ") + std::strerror(errno));
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

std::string readGzip(const std::filesystem::path& path) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (!file) throw InputError(path.string(), "", std::string("cannot read the file: ") + std::strerror(errno));
  std::string out;
  char buffer[1 << 16];
  for (;;) {
    const int n = gzread(file, buffer, sizeof buffer);
    if (n < 0) {
      int code = 0;
      const std::string message = gzerror(file, &code);
      gzclose(file);
      throw InputError(path.string(), "", "not a readable gzip file (zlib: " + message + ")");
    }
    if (n == 0) break;
    out.append(buffer, std::size_t(n));
  }
  gzclose(file);
  return out;
}

std::string quoted(const std::string& token) {
  if (token.empty()) return "the end of the file";
  std::string shown = token.size() > 40 ? token.substr(0, 40) + "..." : token;
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  return "\"" + shown + "\"";
}

}  // namespace

std::optional<std::filesystem::path> FoamFile::locate(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) return path;
  std::filesystem::path gz = path;
  gz += ".gz";
  if (std::filesystem::is_regular_file(gz, ec)) return gz;
  return std::nullopt;
}

FoamFile FoamFile::read(const std::filesystem::path& path) {
  const auto found = locate(path);
  if (!found) throw InputError(path.string(), "", "no such file (nor " + path.filename().string() + ".gz)");
  FoamFile f;
  f.path_ = found->string();
  f.text_ = found->extension() == ".gz" ? readGzip(*found) : readPlain(*found);
  f.parseHeader();
  return f;
}

FoamFile FoamFile::fromText(std::string text, std::string name) {
  FoamFile f;
  f.path_ = std::move(name);
  f.text_ = std::move(text);
  f.parseHeader();
  return f;
}

std::string FoamFile::header(const std::string& key) const {
  const auto it = header_.find(key);
  return it == header_.end() ? std::string() : it->second;
}

int FoamFile::line() const {
  return 1 + int(std::count(text_.begin(), text_.begin() + std::ptrdiff_t(std::min(pos_, text_.size())), '\n'));
}

void FoamFile::fail(const std::string& what, const std::string& message) const {
  throw InputError(path_, what, message + " (line " + std::to_string(line()) + ")");
}

void FoamFile::skipSpace() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (isSpace(c)) {
      ++pos_;
    } else if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/') {
      const auto end = text_.find('\n', pos_);
      pos_ = end == std::string::npos ? text_.size() : end + 1;
    } else if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '*') {
      const auto end = text_.find("*/", pos_ + 2);
      pos_ = end == std::string::npos ? text_.size() : end + 2;
    } else {
      return;
    }
  }
}

char FoamFile::peek() {
  skipSpace();
  return pos_ < text_.size() ? text_[pos_] : '\0';
}

std::string FoamFile::token() {
  skipSpace();
  if (pos_ >= text_.size()) return {};
  const char c = text_[pos_];
  if (isPunctuation(c)) {
    ++pos_;
    return std::string(1, c);
  }
  if (c == '"') {
    const std::size_t start = ++pos_;
    while (pos_ < text_.size() && text_[pos_] != '"') pos_ += text_[pos_] == '\\' ? 2 : 1;
    const std::size_t end = std::min(pos_, text_.size());
    pos_ = std::min(pos_ + 1, text_.size());
    return text_.substr(start, end - start);
  }
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !isSpace(text_[pos_]) && !isPunctuation(text_[pos_]) && text_[pos_] != '"') ++pos_;
  return text_.substr(start, pos_ - start);
}

void FoamFile::parseHeader() {
  pos_ = 0;
  if (token() != "FoamFile")
    fail("FoamFile", "expected the OpenFOAM header \"FoamFile { ... }\" at the start; is this an OpenFOAM file?");
  expect('{', "FoamFile");
  for (;;) {
    const std::string key = token();
    if (key == "}") break;
    if (key.empty() || isPunctuation(key[0])) fail("FoamFile", "expected a header entry or '}', got " + quoted(key));
    std::string value;
    for (std::string t = token(); t != ";"; t = token()) {
      if (t.empty() || t == "}") fail("FoamFile/" + key, "expected ';' after the header entry");
      value += (value.empty() ? "" : " ") + t;
    }
    header_[key] = value;
  }
  bodyStart_ = pos_;
  const std::string format = header("format");
  if (format == "binary") binary_ = true;
  else if (format != "ascii" && !format.empty())
    fail("FoamFile/format", "expected ascii or binary, got " + quoted(format));
  const std::string arch = header("arch");
  if (arch.find("MSB") != std::string::npos)
    fail("FoamFile/arch", "big-endian (MSB) binary files are not supported; convert with foamFormatConvert -ascii");
  if (arch.find("label=64") != std::string::npos) labelBytes_ = 8;
  if (arch.find("scalar=32") != std::string::npos) scalarBytes_ = 4;
}

void FoamFile::expect(char c, const std::string& what) {
  skipSpace();
  if (pos_ >= text_.size() || text_[pos_] != c) {
    const std::size_t save = pos_;
    const std::string got = token();
    pos_ = save;
    fail(what, std::string("expected '") + c + "', got " + quoted(got));
  }
  ++pos_;
}

std::string FoamFile::word(const std::string& what) {
  const std::string t = token();
  if (t.empty() || (t.size() == 1 && isPunctuation(t[0]))) fail(what, "expected a word or number, got " + quoted(t));
  return t;
}

double FoamFile::scalar(const std::string& what) {
  const std::string t = token();
  char* end = nullptr;
  errno = 0;
  const double v = t.empty() ? 0.0 : std::strtod(t.c_str(), &end);
  // strtod reports ERANGE for subnormal results too (OpenFOAM writes values like 9e-42): only an
  // overflow, which returns infinity, is refused.
  if (t.empty() || end != t.c_str() + t.size()) fail(what, "expected a number, got " + quoted(t));
  if (!std::isfinite(v)) fail(what, "expected a finite number, got " + quoted(t));
  return v;
}

std::int64_t FoamFile::label(const std::string& what) {
  const std::string t = token();
  char* end = nullptr;
  errno = 0;
  const long long v = t.empty() ? 0 : std::strtoll(t.c_str(), &end, 10);
  if (t.empty() || end != t.c_str() + t.size() || errno == ERANGE)
    fail(what, "expected a whole number (label), got " + quoted(t));
  return std::int64_t(v);
}

void FoamFile::skipEntry() {
  int depth = 0;
  for (;;) {
    const std::string t = token();
    if (t.empty()) return;
    if (t == "{" || t == "(" || t == "[") ++depth;
    else if (t == "}" || t == ")" || t == "]") {
      if (--depth <= 0 && t == "}") return;  // a dictionary entry `name { ... }` has no ';'
    } else if (t == ";" && depth <= 0) {
      return;
    }
  }
}

bool FoamFile::seekKeyword(const std::string& keyword) {
  pos_ = bodyStart_;
  for (;;) {
    const std::string t = token();
    if (t.empty()) return false;
    if (t == keyword) return true;
    skipEntry();
  }
}

template <class T>
std::vector<T> FoamFile::numericList(const std::string& what, int components, bool labels) {
  const auto item = [&](const std::string& w) -> T {
    if constexpr (std::is_same_v<T, double>) return scalar(w);
    else return label(w);
  };
  const auto readItem = [&](std::vector<T>& out) {
    if (components == 1) {
      out.push_back(item(what));
      return;
    }
    expect('(', what);
    for (int c = 0; c < components; ++c) out.push_back(item(what));
    expect(')', what);
  };
  std::vector<T> out;
  skipSpace();
  if (peek() == '(' && !binary_) {  // a list without its size (valid in hand-written ASCII files)
    expect('(', what);
    while (peek() != ')') {
      if (peek() == '\0') fail(what, "expected ')' closing the list, got the end of the file");
      readItem(out);
    }
    expect(')', what);
    return out;
  }
  const std::int64_t n = label(what + " size");
  if (n < 0) fail(what, "expected a list size >= 0, got " + std::to_string(n));
  const char open = peek();
  if (open == '{') {  // N{value}: N equal items
    expect('{', what);
    std::vector<T> one;
    readItem(one);
    expect('}', what);
    out.reserve(std::size_t(n) * components);
    for (std::int64_t i = 0; i < n; ++i) out.insert(out.end(), one.begin(), one.end());
    return out;
  }
  if (binary_) {
    expect('(', what);
    const int bytes = labels ? labelBytes_ : scalarBytes_;
    const std::size_t count = std::size_t(n) * std::size_t(components);
    if (text_.size() - pos_ < count * std::size_t(bytes) + 1)
      fail(what, "binary list of " + std::to_string(n) + " items of " + std::to_string(components * bytes) +
                     " bytes runs past the end of the file (truncated, or the header's arch does not match)");
    const char* data = text_.data() + pos_;
    out.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      const char* p = data + i * std::size_t(bytes);
      if (labels) {
        if (bytes == 8) { std::int64_t v; std::memcpy(&v, p, 8); out[i] = T(v); }
        else { std::int32_t v; std::memcpy(&v, p, 4); out[i] = T(v); }
      } else {
        double v;
        if (bytes == 8) std::memcpy(&v, p, 8);
        else { float f; std::memcpy(&f, p, 4); v = f; }
        if (!std::isfinite(v)) fail(what, "item " + std::to_string(i / components) + " is not a finite number");
        out[i] = T(v);
      }
    }
    pos_ += count * std::size_t(bytes);
    if (text_[pos_] != ')')
      fail(what, "expected ')' right after the " + std::to_string(n) +
                     " binary items (the list is longer than its size, or the header's arch does not match)");
    ++pos_;
    return out;
  }
  expect('(', what);
  out.reserve(std::size_t(n) * components);
  for (std::int64_t i = 0; i < n; ++i) {
    if (peek() == ')')
      fail(what, "the list ends after " + std::to_string(i) + " items; its size says " + std::to_string(n));
    readItem(out);
  }
  if (peek() != ')') fail(what, "expected ')' after " + std::to_string(n) + " items: the list is longer than its size");
  expect(')', what);
  return out;
}

std::vector<double> FoamFile::scalarList(const std::string& what) { return numericList<double>(what, 1, false); }
std::vector<double> FoamFile::vectorList(const std::string& what) { return numericList<double>(what, 3, false); }
std::vector<std::int64_t> FoamFile::labelList(const std::string& what) {
  return numericList<std::int64_t>(what, 1, true);
}

void FoamFile::labelListList(const std::string& what, std::vector<std::int64_t>& offsets,
                             std::vector<std::int64_t>& labels) {
  offsets.assign(1, 0);
  labels.clear();
  const std::int64_t n = label(what + " size");
  if (n < 0) fail(what, "expected a list size >= 0, got " + std::to_string(n));
  expect('(', what);
  offsets.reserve(std::size_t(n) + 1);
  for (std::int64_t i = 0; i < n; ++i) {
    if (peek() == ')')
      fail(what, "the list ends after " + std::to_string(i) + " items; its size says " + std::to_string(n));
    const auto item = labelList(what + " item " + std::to_string(i));
    labels.insert(labels.end(), item.begin(), item.end());
    offsets.push_back(std::int64_t(labels.size()));
  }
  expect(')', what);
}

const char* FoamFile::rawRecord(std::size_t count, const std::string& what) {
  expect('(', what);
  if (text_.size() - pos_ < count + 1) fail(what, "binary record of " + std::to_string(count) + " bytes runs past the end of the file");
  const char* p = text_.data() + pos_;
  pos_ += count;
  if (text_[pos_] != ')')
    fail(what, "expected ')' after a binary record of " + std::to_string(count) +
                   " bytes (not the legacy position form, or the header's arch does not match)");
  ++pos_;
  return p;
}

}  // namespace rcfd::openfoam
