#include "core/Errors.hpp"

namespace rcfd {
namespace {
std::string describe(const std::string& source, const std::vector<Violation>& violations) {
  std::string text = source + ": " + std::to_string(violations.size()) +
                     (violations.size() == 1 ? " problem" : " problems");
  for (const auto& v : violations) {
    text += "\n  " + (v.pointer.empty() ? std::string("(document)") : v.pointer) + ": " + v.message;
  }
  return text;
}
}  // namespace

InputError::InputError(std::string source, std::vector<Violation> violations)
    : std::runtime_error(describe(source, violations)),
      source_(std::move(source)),
      violations_(std::move(violations)) {}

InputError::InputError(std::string source, std::string pointer, std::string message)
    : InputError(std::move(source), std::vector<Violation>{{std::move(pointer), std::move(message)}}) {}

}  // namespace rcfd
