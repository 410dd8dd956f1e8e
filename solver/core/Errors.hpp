#pragma once
/// \file Errors.hpp
/// The three ways a run can end other than success, mapped to exit codes by every front end
/// (rcfd-solve: 2 invalid input, 3 numerical or I/O failure, 130 cancelled; the server: 4xx/5xx).

#include <stdexcept>
#include <string>
#include <vector>

namespace rcfd {

/// One broken rule in an input document: where (RFC 6901 JSON pointer, or a file/dataset path) and what.
struct Violation {
  std::string pointer;  ///< e.g. "/spray/cone_half_angle_deg" or "/frames/alpha_p"
  std::string message;  ///< the value and the rule, e.g. "95 is above the maximum 90 (exclusive)"
};

/// Invalid input: a scene, job file or database that breaks a rule. Carries every violation found,
/// not only the first. Exit code 2.
class InputError : public std::runtime_error {
 public:
  InputError(std::string source, std::vector<Violation> violations);
  InputError(std::string source, std::string pointer, std::string message);

  const std::string& source() const { return source_; }
  const std::vector<Violation>& violations() const { return violations_; }

 private:
  std::string source_;
  std::vector<Violation> violations_;
};

/// The run failed numerically or on I/O; the message says what and where. Exit code 3.
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The run was cancelled (SIGINT/SIGTERM) after writing its checkpoint. Exit code 130.
class Cancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace exit_code {
inline constexpr int success = 0;
inline constexpr int invalid_input = 2;
inline constexpr int run_failed = 3;
inline constexpr int cancelled = 130;
}  // namespace exit_code

}  // namespace rcfd
