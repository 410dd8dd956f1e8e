#pragma once
/// \file Users.hpp
/// Who is calling: the users the server knows (--users-file: one line `NAME ROLE SHA256HEX` per user)
/// or, without such a file, the one shared token, which acts as the user `admin` with the admin role.
/// Only SHA-256 digests of tokens are kept: a presented token is hashed and compared with every
/// user's digest in constant time, so neither the file nor the comparison's timing gives a token away.

#include <array>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rcfd::server {

/// The user a request acts for. A plain user sees and acts on their own jobs and databases only; an
/// admin on everyone's.
struct Caller {
  std::string name;
  bool admin = false;
  /// Whether this caller may see and act on something owned by `owner`.
  bool mayAccess(const std::string& owner) const { return admin || owner == name; }
};

/// The owner of everything made before the server knew users, and the user the single token acts as.
inline constexpr const char* kDefaultOwner = "admin";

/// A users file that cannot be used; the message names the file and, for a bad line, its number.
class UsersFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class UserDirectory {
 public:
  using Digest = std::array<unsigned char, 32>;

  /// The single-token server: `token` authenticates as `admin` (role admin).
  static UserDirectory singleToken(const std::string& token);
  /// Parses a users file: `NAME ROLE SHA256HEX` per line (ROLE `user` or `admin`; the hex digest of the
  /// token, in either case, optionally followed by `-` as `sha256sum` prints it for stdin), `#` starts
  /// a comment, blank lines are skipped. Names are 1-64 of [A-Za-z0-9._-] starting with a letter or
  /// digit, each at most once, as each digest. Throws UsersFileError naming the first bad line.
  static UserDirectory parse(std::string_view text, const std::string& source);
  /// Reads and parses `path`. A file others or its group may write is refused (anyone could add an
  /// admin); one they may read gives `warning` a text to print (the digests of weak tokens can be
  /// guessed offline).
  static UserDirectory load(const std::filesystem::path& path, std::string& warning);

  /// The user whose token this is; nullopt for any other. Every user's digest is compared, whatever
  /// matched, so the time taken does not depend on which user (if any) the token belongs to.
  std::optional<Caller> authenticate(std::string_view token) const;

  std::size_t size() const { return users_.size(); }

  /// SHA-256 of `data`.
  static Digest sha256(std::string_view data);

 private:
  struct User {
    Caller caller;
    Digest digest{};
  };
  std::vector<User> users_;
};

}  // namespace rcfd::server
