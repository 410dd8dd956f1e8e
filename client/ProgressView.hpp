#pragma once
/// \file ProgressView.hpp
/// Shows a job's progress on stderr while `rcfd wait` polls: a one-line bar with ETA redrawn in place on a
/// terminal, plain lines (one per change) when stderr is a file or pipe.

#include <nlohmann/json.hpp>
#include <string>

namespace rcfd::client {

class ProgressView {
 public:
  explicit ProgressView(bool terminal) : terminal_(terminal) {}
  /// Shows the job resource (GET /v1/jobs/{id}) if anything changed since the last call.
  void update(const nlohmann::json& job);
  /// Ends the bar's line on a terminal.
  void finish();

 private:
  bool terminal_;
  std::string last_;
  bool drawn_ = false;
};

/// "1h02m", "4m10s", "12s".
std::string formatDuration(double seconds);

}  // namespace rcfd::client
