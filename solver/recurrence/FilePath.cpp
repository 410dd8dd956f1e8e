// A predefined recurrence path ("file"): the frame indices come from a file (PathFile.hpp), checked
// against the database's frame count. The seed is not used. The file must hold at least as many
// entries as steps are requested; a shorter file is refused rather than repeated, since wrapping
// around would add a jump the file's author did not choose.

#include "core/Errors.hpp"
#include "recurrence/PathFile.hpp"
#include "recurrence/PathSupport.hpp"
#include "recurrence/RecurrencePath.hpp"

namespace rcfd {
namespace {

class FilePathGenerator final : public PathGenerator {
 public:
  explicit FilePathGenerator(const PathSpec& spec) : file_(spec.file) {
    if (file_.empty()) {
      throw InputError("scene", "/rcfd/path/file", "is required when /rcfd/path/type is \"file\"");
    }
    path_ = readPathFile(file_);
  }

  RecurrencePath generate(const Eigen::MatrixXf& R, std::int64_t steps, std::uint64_t) const override {
    checkPathRecurrence(R);
    checkSteps(steps);
    const int n = int(R.rows());
    if (std::int64_t(path_.frames.size()) < steps) {
      throw InputError(file_, "/rcfd/path/file",
                       "holds " + std::to_string(path_.frames.size()) + " frame indices; " +
                           std::to_string(steps) + " steps are requested");
    }
    for (std::size_t i = 0; i < std::size_t(steps); ++i) {
      if (path_.frames[i] >= n) {
        throw InputError(file_, "/rcfd/path/file",
                         "entry " + std::to_string(i) + " is frame " + std::to_string(path_.frames[i]) +
                             "; the database has frames 0.." + std::to_string(n - 1));
      }
    }
    RecurrencePath out;
    out.frames.assign(path_.frames.begin(), path_.frames.begin() + steps);
    return out;
  }

 private:
  std::string file_;
  RecurrencePath path_;
};

const bool registered = PathGeneratorRegistry::add(
    "file", "a predefined path: frame indices from a text or HDF5 file (/rcfd/path/file)",
    [](const PathSpec& spec) { return std::make_unique<FilePathGenerator>(spec); });

}  // namespace
}  // namespace rcfd
