#include "jobs/JobRunner.hpp"

#include <filesystem>
#include <fstream>

#include "core/Errors.hpp"

namespace rcfd {

void writeFileAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw RunError("cannot write " + tmp);
    out << text;
    if (!out.flush()) throw RunError("failed writing " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

nlohmann::json runJob(const JobSpec& job, const RunOptions& options) {
  if (!JobRunnerRegistry::contains(job.kind)) {
    throw InputError("job", "/kind", "no runner for job kind \"" + job.kind + "\" in this build; available: " +
                                         [] {
                                           std::string s;
                                           for (const auto& n : JobRunnerRegistry::names()) s += n + " ";
                                           return s;
                                         }());
  }
  std::filesystem::create_directories(options.outDir);
  auto runner = JobRunnerRegistry::create(job.kind);
  nlohmann::json summary = runner->run(job, options);
  writeFileAtomically(options.outDir + "/summary.json", summary.dump(2) + "\n");
  return summary;
}

}  // namespace rcfd
