#include "Users.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <sys/stat.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

namespace rcfd::server {

namespace {

constexpr std::size_t kMaxName = 64;

bool isName(const std::string& name) {
  if (name.empty() || name.size() > kMaxName || !std::isalnum(static_cast<unsigned char>(name[0]))) return false;
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') return false;
  return true;
}

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::optional<UserDirectory::Digest> parseDigest(const std::string& hex) {
  UserDirectory::Digest digest{};
  if (hex.size() != 2 * digest.size()) return std::nullopt;
  for (std::size_t i = 0; i < digest.size(); ++i) {
    const int high = hexValue(hex[2 * i]), low = hexValue(hex[2 * i + 1]);
    if (high < 0 || low < 0) return std::nullopt;
    digest[i] = static_cast<unsigned char>(16 * high + low);
  }
  return digest;
}

/// A short, printable quote of a field from the file, for error messages.
std::string quoted(const std::string& field) {
  std::string out = "\"";
  for (const char c : field.substr(0, 40)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return out + (field.size() > 40 ? "...\"" : "\"");
}

}  // namespace

UserDirectory::Digest UserDirectory::sha256(std::string_view data) {
  Digest out{};
  unsigned int length = 0;
  if (EVP_Digest(data.data(), data.size(), out.data(), &length, EVP_sha256(), nullptr) != 1 ||
      length != out.size())
    throw std::runtime_error("SHA-256 failed");
  return out;
}

UserDirectory UserDirectory::singleToken(const std::string& token) {
  UserDirectory directory;
  directory.users_.push_back({Caller{kDefaultOwner, true}, sha256(token)});
  return directory;
}

UserDirectory UserDirectory::parse(std::string_view text, const std::string& source) {
  UserDirectory directory;
  std::set<std::string> names;
  std::set<Digest> digests;
  std::istringstream lines{std::string(text)};
  int number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++number;
    const auto fail = [&](const std::string& what) {
      return UsersFileError(source + " line " + std::to_string(number) + ": " + what +
                            " (each line: NAME ROLE SHA256HEX, ROLE user or admin)");
    };
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::vector<std::string> words;
    for (std::string word; fields >> word;) words.push_back(word);
    if (words.empty()) continue;
    // `sha256sum` prints "HEX  -" for its standard input: the "-" may stay on the line.
    if (words.size() == 4 && words[3] == "-") words.pop_back();
    if (words.size() != 3)
      throw fail("expected 3 fields, found " + std::to_string(words.size()));
    const std::string &name = words[0], &role = words[1], &hex = words[2];
    if (!isName(name))
      throw fail("user name " + quoted(name) + " is not 1-64 of A-Z a-z 0-9 . _ - starting with a letter or digit");
    if (role != "user" && role != "admin") throw fail("role " + quoted(role) + " is not user or admin");
    const auto digest = parseDigest(hex);
    if (!digest)
      throw fail(quoted(hex) + " is not a SHA-256 digest in hex (64 digits; printf %s TOKEN | sha256sum)");
    if (!names.insert(name).second) throw fail("user " + quoted(name) + " appears twice");
    if (!digests.insert(*digest).second)
      throw fail("user " + quoted(name) + " has the same token as a user above; every user needs their own");
    directory.users_.push_back({Caller{name, role == "admin"}, *digest});
  }
  if (directory.users_.empty()) throw UsersFileError(source + ": no users (each line: NAME ROLE SHA256HEX)");
  return directory;
}

UserDirectory UserDirectory::load(const std::filesystem::path& path, std::string& warning) {
  const std::string source = "users file " + path.string();
  std::ifstream in(path, std::ios::binary);
  struct stat st {};
  if (!in || ::stat(path.c_str(), &st) != 0)
    throw UsersFileError("cannot read " + source + ": " + std::strerror(errno));
  if (st.st_mode & (S_IWGRP | S_IWOTH))
    throw UsersFileError(source + " may be written by its group or others, who could add themselves as admin: chmod 600 " +
                         path.string());
  if (st.st_mode & (S_IRGRP | S_IROTH)) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    warning = source + " is readable by its group or others (mode " + mode +
              "): a weak token can be guessed from its digest offline; chmod 600 " + path.string();
  }
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  return parse(text, source);
}

std::optional<Caller> UserDirectory::authenticate(std::string_view token) const {
  if (token.empty()) return std::nullopt;
  const Digest presented = sha256(token);
  const User* match = nullptr;
  for (const User& user : users_) {
    const bool same = CRYPTO_memcmp(presented.data(), user.digest.data(), presented.size()) == 0;
    if (same) match = &user;  // no early exit: every digest is compared
  }
  if (!match) return std::nullopt;
  return match->caller;
}

}  // namespace rcfd::server
