#include "jobs/JobRunner.hpp"

#include <filesystem>
#include <fstream>

#include "core/Errors.hpp"
#include "core/Isa.hpp"

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
  auto runner = JobRunnerRegistry::createAt("job", "/kind", job.kind);  // an unknown kind makes no DIR
  std::filesystem::create_directories(options.outDir);
  nlohmann::json summary = runner->run(job, options);
  summary["kernel_isa"] = isaName(kernelIsa());  // which bits to expect (docs/contracts.md, "Determinism")
  writeFileAtomically(options.outDir + "/summary.json", summary.dump(2) + "\n");
  return summary;
}

}  // namespace rcfd
