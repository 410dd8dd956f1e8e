#include "SolverRun.hpp"

#include <signal.h>

#include <fstream>
#include <optional>
#include <stdexcept>

#include "DatabaseRef.hpp"

namespace rcfd::server {

namespace {

constexpr std::size_t kReasonLines = 6;       // stderr lines quoted in a failure reason
constexpr std::size_t kReasonMaxChars = 2000;

std::optional<double> optionalNumber(const nlohmann::json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_number()) return std::nullopt;
  return it->get<double>();
}

/// The phase a progress line names: a short word ("fill", "run"), empty when absent or not one.
std::string phaseOf(const nlohmann::json& j) {
  constexpr std::size_t kPhaseMaxChars = 32;
  auto it = j.find("phase");
  if (it == j.end() || !it->is_string()) return {};
  const std::string& phase = it->get_ref<const std::string&>();
  return phase.size() <= kPhaseMaxChars ? phase : std::string();
}




/// Coverage histogram bins from summary.json (coverage.histogram.{edges,counts}; docs/contracts.md,
/// "summary.json").
std::vector<CoverageBin> coverageBins(const nlohmann::json& summary) {
  std::vector<CoverageBin> bins;
  const auto cov = summary.find("coverage");
  if (cov == summary.end() || !cov->is_object()) return bins;
  const auto hist = cov->find("histogram");
  if (hist == cov->end() || !hist->is_object()) return bins;
  const auto& edges = hist->value("edges", nlohmann::json::array());
  const auto& counts = hist->value("counts", nlohmann::json::array());
  if (!edges.is_array() || !counts.is_array() || edges.size() != counts.size() + 1) return bins;
  for (std::size_t i = 0; i < counts.size(); ++i)
    bins.push_back({edges[i].get<double>(), edges[i + 1].get<double>(), counts[i].get<double>()});
  return bins;
}

}  // namespace

void storeProgress(JobStore& store, const std::string& id, const nlohmann::json& p) {
  const auto number = [&](const char* key) { return optionalNumber(p, key); };
  store.updateProgress(id, number("fraction").value_or(0.0), number("sim_time"), number("wall_time"),
                       number("eta_s"), phaseOf(p), number("phase_fraction"));
}

std::string logTail(const std::filesystem::path& log, std::streamoff from) {
  std::ifstream in(log, std::ios::binary);
  if (!in) return {};
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  // Read at most the last 64 KiB of this attempt's output.
  const std::streamoff start = std::max(from, size - std::streamoff(64 * 1024));
  in.seekg(start);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") != std::string::npos) lines.push_back(line);
  }
  std::string out;
  const std::size_t first = lines.size() > kReasonLines ? lines.size() - kReasonLines : 0;
  for (std::size_t i = first; i < lines.size(); ++i) out += (out.empty() ? "" : "\n") + lines[i];
  if (out.size() > kReasonMaxChars) out = "..." + out.substr(out.size() - kReasonMaxChars);
  return out;
}

std::string signalName(int sig) {
  const char* abbrev = sigabbrev_np(sig);
  std::string name = abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(sig);
  return name + " (" + std::to_string(sig) + ")";
}

void writeJobFile(JobStore& store, const ServerConfig& config, const JobRecord& job) {
  namespace fs = std::filesystem;
  const fs::path dir = config.jobDir(job.id);
  fs::create_directories(dir);
  auto document = nlohmann::json::parse(job.request);
  if (!job.databaseRef.empty()) {
    const DatabaseRef ref = resolveDatabaseRef(store, config, job.databaseRef);
    document["database"] = fs::absolute(ref.path).string();
  }
  if (job.kind == "import" && document.contains("case_dir"))  // checked at submit: inside the import root
    document["case_dir"] = importCaseDirectory(config.importRoot, document["case_dir"].get<std::string>()).string();
  {
    std::ofstream out(dir / "job.json.tmp");
    out << document.dump(2) << "\n";
    if (!out) throw std::runtime_error("cannot write " + (dir / "job.json").string());
  }
  fs::rename(dir / "job.json.tmp", dir / "job.json");
}

bool databaseReady(JobStore& store, const ServerConfig& config, const JobRecord& job) {
  if (job.databaseRef.empty()) return true;
  const DatabaseRef ref = resolveDatabaseRef(store, config, job.databaseRef);
  switch (ref.status) {
    case DatabaseRef::Status::ready:
      return true;
    case DatabaseRef::Status::pending:
      return false;
    default:
      store.transition(job.id, state::queued, state::failed, {}, "its database cannot be used: " + ref.detail);
      return false;
  }
}

void storeSucceeded(JobStore& store, const ServerConfig& config, const std::string& id, const std::string& from) {
  std::ifstream in(config.jobDir(id) / "summary.json");
  auto summary = nlohmann::json::parse(in, nullptr, false);
  if (!in || summary.is_discarded() || !summary.is_object()) {
    store.transition(id, from, state::failed, {},
                     "the solver exited 0 but summary.json is missing or not a JSON object");
    return;
  }
  store.markSucceeded(id, summary, coverageBins(summary));
}

}  // namespace rcfd::server
