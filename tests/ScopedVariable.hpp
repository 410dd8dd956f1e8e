#pragma once
// An environment variable set (or unset) for a scope and restored after it: tests that pick the
// kernels' variant with RCFD_ISA (core/Isa.hpp).
#include <cstdlib>
#include <optional>
#include <string>

namespace rcfd::test {

class ScopedVariable {
 public:
  /// Sets `name` to `value`, or unsets it for nullopt.
  ScopedVariable(const char* name, std::optional<std::string> value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) {
      ::setenv(name, value->c_str(), 1);
    } else {
      ::unsetenv(name);
    }
  }
  ~ScopedVariable() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  ScopedVariable(const ScopedVariable&) = delete;
  ScopedVariable& operator=(const ScopedVariable&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

}  // namespace rcfd::test
