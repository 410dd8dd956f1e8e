#include "CoverageExport.hpp"

#include <hdf5.h>

#include <cstdio>

#include "Ids.hpp"

namespace rcfd::server {

std::mutex& hdf5Mutex() {
  static std::mutex instance;
  return instance;
}

std::vector<CoverageBin> mergeBins(const std::vector<CoverageBin>& stored, std::size_t n) {
  const std::size_t group = stored.size() / n;
  std::vector<CoverageBin> out;
  for (std::size_t i = 0; i < n; ++i) {
    CoverageBin b{stored[i * group].lower, stored[i * group + group - 1].upper, 0.0};
    for (std::size_t k = 0; k < group; ++k) b.count += stored[i * group + k].count;
    out.push_back(b);
  }
  return out;
}

std::string divisorsText(std::size_t n) {
  std::string out;
  for (std::size_t d = 1; d <= n; ++d)
    if (n % d == 0) out += (out.empty() ? "" : ", ") + std::to_string(d);
  return out;
}

nlohmann::json coverageJson(const std::string& jobId, const std::vector<CoverageBin>& bins) {
  nlohmann::json edges = nlohmann::json::array(), counts = nlohmann::json::array();
  for (const auto& b : bins) {
    edges.push_back(b.lower);
    counts.push_back(b.count);
  }
  if (!bins.empty()) edges.push_back(bins.back().upper);
  return {{"job", jobId}, {"bins", bins.size()}, {"edges", edges}, {"counts", counts}};
}

std::string coverageCsv(const std::vector<CoverageBin>& bins) {
  std::string out = "lower,upper,count\n";
  char line[128];
  for (const auto& b : bins) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", b.lower, b.upper, b.count);
    out += line;
  }
  return out;
}

namespace {
bool writeDataset(hid_t file, const char* name, const std::vector<double>& values) {
  const hsize_t dims[1] = {values.size()};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t set =
      H5Dcreate2(file, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const bool ok =
      set >= 0 && H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0;
  if (set >= 0) H5Dclose(set);
  H5Sclose(space);
  return ok;
}
}  // namespace

bool writeCoverageH5(const std::filesystem::path& path, const std::string& jobId,
                     const std::vector<CoverageBin>& bins, std::string& error) {
  std::vector<double> edges, counts;
  for (const auto& b : bins) {
    edges.push_back(b.lower);
    counts.push_back(b.count);
  }
  edges.push_back(bins.back().upper);
  const auto tmp = path.string() + "." + newId();
  std::lock_guard lock(hdf5Mutex());
  const hid_t file = H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) {
    error = "cannot create " + tmp;
    return false;
  }
  bool ok = writeDataset(file, "/edges", edges) && writeDataset(file, "/counts", counts);
  // The job id as a string attribute on the root group, so a downloaded file says where it came from.
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, jobId.size());
  const hid_t scalar = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(file, "job", type, scalar, H5P_DEFAULT, H5P_DEFAULT);
  ok = ok && attr >= 0 && H5Awrite(attr, type, jobId.data()) >= 0;
  if (attr >= 0) H5Aclose(attr);
  H5Sclose(scalar);
  H5Tclose(type);
  ok = H5Fclose(file) >= 0 && ok;
  std::error_code ec;
  if (ok) std::filesystem::rename(tmp, path, ec);
  if (!ok || ec) {
    std::filesystem::remove(tmp, ec);
    error = "cannot write the coverage HDF5 file " + path.string();
    return false;
  }
  return true;
}

}  // namespace rcfd::server
