#include "ProgressView.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>

namespace rcfd::client {

std::string formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  char out[32];
  if (s >= 3600) std::snprintf(out, sizeof out, "%ldh%02ldm", s / 3600, (s % 3600) / 60);
  else if (s >= 60) std::snprintf(out, sizeof out, "%ldm%02lds", s / 60, s % 60);
  else std::snprintf(out, sizeof out, "%lds", s);
  return out;
}

void ProgressView::update(const nlohmann::json& job) {
  const std::string state = job.value("state", "?");
  const auto& p = job.contains("progress") ? job["progress"] : nlohmann::json::object();
  const double fraction = p.value("fraction", 0.0);
  const auto number = [&](const char* key) {
    return p.contains(key) && p[key].is_number() ? p[key].get<double>() : NAN;
  };
  const double simTime = number("sim_time"), eta = number("eta_s"), phaseFraction = number("phase_fraction");
  // The phase only while the job runs: a finished job's last phase says nothing.
  const bool running = state == "RUNNING" || state == "CANCELLING";
  const std::string phase = running && p.contains("phase") && p["phase"].is_string() ? p["phase"].get<std::string>() : "";
  char text[256];
  std::string line;
  if (terminal_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * kWidth);
    std::snprintf(text, sizeof text, "%-10s [%s%s] %5.1f%%", state.c_str(),
                  std::string(static_cast<std::size_t>(filled), '#').c_str(),
                  std::string(static_cast<std::size_t>(kWidth - filled), ' ').c_str(), 100 * fraction);
    line = text;
    if (!phase.empty()) {
      line += "  " + phase;
      if (std::isfinite(phaseFraction)) {
        std::snprintf(text, sizeof text, " %.0f%%", 100 * phaseFraction);
        line += text;
      }
    }
    if (std::isfinite(simTime)) line += "  sim " + formatDuration(simTime);
    if (std::isfinite(eta) && state == "RUNNING") line += "  ETA " + formatDuration(eta);
  } else {
    std::snprintf(text, sizeof text, "%s %.1f%%", state.c_str(), 100 * fraction);
    line = text;
    if (!phase.empty()) line += " phase=" + phase;
    if (!phase.empty() && std::isfinite(phaseFraction)) {
      std::snprintf(text, sizeof text, " phase_fraction=%.2f", phaseFraction);
      line += text;
    }
    if (std::isfinite(simTime)) line += " sim_time=" + std::to_string(simTime) + "s";
    if (std::isfinite(eta) && state == "RUNNING") line += " eta=" + formatDuration(eta);
  }
  if (line == last_) return;
  last_ = line;
  if (terminal_) {
    std::cerr << "\r\033[K" << line << std::flush;
    drawn_ = true;
  } else {
    std::cerr << line << std::endl;
  }
}

void ProgressView::finish() {
  if (terminal_ && drawn_) std::cerr << "\n";
  drawn_ = false;
}

}  // namespace rcfd::client
