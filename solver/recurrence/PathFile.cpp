#include "recurrence/PathFile.hpp"

#include <cctype>
#include <fstream>
#include <sstream>

#include "core/Errors.hpp"
#include "core/Hdf5.hpp"

namespace rcfd {

namespace {
bool isHdf5Name(const std::string& path) {
  auto ends = [&](const std::string& s) {
    return path.size() >= s.size() && path.compare(path.size() - s.size(), s.size(), s) == 0;
  };
  return ends(".h5") || ends(".hdf5");
}
}  // namespace

RecurrencePath readPathFile(const std::string& path) {
  RecurrencePath out;
  if (isHdf5Name(path)) {
    h5::silenceErrors();
    if (H5Fis_hdf5(path.c_str()) <= 0) throw InputError(path, "", "not an HDF5 file (or missing)");
    h5::Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
    if (!file.valid() || !h5::linkExists(file, "/path")) throw InputError(path, "/path", "dataset is missing");
    h5::Handle set(H5Dopen2(file, "/path", H5P_DEFAULT));
    const auto dims = h5::datasetDims(set);
    if (dims.size() != 1 || h5::datasetClass(set) != H5T_INTEGER) {
      throw InputError(path, "/path", "must be a 1-D integer dataset of frame indices");
    }
    std::vector<long long> values(dims[0]);
    if (!values.empty() &&
        H5Dread(set, H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0) {
      throw InputError(path, "/path", "could not be read");
    }
    out.frames.reserve(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (values[i] < 0 || values[i] > (1LL << 30)) {
        throw InputError(path, "/path", "entry " + std::to_string(i) + " is " + std::to_string(values[i]) +
                                            "; frame indices are >= 0");
      }
      out.frames.push_back(int(values[i]));
    }
    return out;
  }
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "cannot be opened");
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string word;
    while (words >> word) {
      std::size_t used = 0;
      long long v = -1;
      try {
        v = std::stoll(word, &used);
      } catch (...) {
        used = 0;
      }
      if (used != word.size() || v < 0 || v > (1LL << 30)) {
        throw InputError(path, "line " + std::to_string(lineNo),
                         "\"" + word + "\" is not a frame index (a whole number >= 0)");
      }
      out.frames.push_back(int(v));
    }
  }
  return out;
}

void writePathFile(const std::string& path, const RecurrencePath& recurrencePath) {
  if (isHdf5Name(path)) {
    h5::silenceErrors();
    h5::Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT));
    if (!file.valid()) throw RunError(path + ": cannot create the path file");
    const hsize_t n = recurrencePath.frames.size();
    h5::Handle space = h5::check(H5Screate_simple(1, &n, nullptr), path);
    h5::Handle set = h5::check(
        H5Dcreate2(file, "/path", H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path);
    if (n > 0)
      h5::checkStatus(H5Dwrite(set, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, recurrencePath.frames.data()),
                      path + ": writing /path");
    return;
  }
  std::ofstream out(path);
  if (!out) throw RunError(path + ": cannot create the path file");
  out << "# rcfd recurrence path: one frame index per step\n";
  for (int f : recurrencePath.frames) out << f << "\n";
  if (!out) throw RunError(path + ": writing the path file failed");
}

}  // namespace rcfd
