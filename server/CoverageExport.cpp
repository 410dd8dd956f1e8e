#include "CoverageExport.hpp"

#include <hdf5.h>

#include <cstdio>

#include "Ids.hpp"
#include "analysis/EnsembleStatistics.hpp"

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

std::optional<CoverageBand> coverageBand(const nlohmann::json& summary, std::size_t bins) {
  const nlohmann::json::json_pointer at("/ensemble/coverage/histogram/member_counts");
  if (!summary.is_object() || !summary.contains(at) || !summary.at(at).is_array() || bins == 0) return std::nullopt;
  std::vector<std::vector<double>> members;
  try {
    members = summary.at(at).get<std::vector<std::vector<double>>>();
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
  if (members.empty()) return std::nullopt;
  const std::size_t stored = members.front().size();
  if (stored == 0 || stored % bins != 0) return std::nullopt;
  const std::size_t group = stored / bins;
  CoverageBand band;
  band.members = int(members.size());
  std::vector<double> values;
  for (std::size_t b = 0; b < bins; ++b) {
    values.clear();
    for (const auto& m : members) {
      if (m.size() != stored) return std::nullopt;
      double sum = 0.0;
      for (std::size_t k = 0; k < group; ++k) sum += m[b * group + k];
      values.push_back(sum);
    }
    const auto s = rcfd::analysis::spreadOf(values);
    band.mean.push_back(s.mean), band.sd.push_back(s.sd), band.sem.push_back(s.sem);
    band.ciLow.push_back(s.ciLow), band.ciHigh.push_back(s.ciHigh);
    band.min.push_back(s.min), band.max.push_back(s.max);
  }
  return band;
}

nlohmann::json coverageJson(const std::string& jobId, const std::vector<CoverageBin>& bins,
                            const CoverageBand* band) {
  nlohmann::json edges = nlohmann::json::array(), counts = nlohmann::json::array();
  for (const auto& b : bins) {
    edges.push_back(b.lower);
    counts.push_back(b.count);
  }
  if (!bins.empty()) edges.push_back(bins.back().upper);
  nlohmann::json out = {{"job", jobId}, {"bins", bins.size()}, {"edges", edges}, {"counts", counts}};
  if (band) {
    out["ensemble"] = {{"members", band->members}, {"mean", band->mean},       {"sd", band->sd},
                       {"sem", band->sem},         {"ci95_low", band->ciLow}, {"ci95_high", band->ciHigh},
                       {"min", band->min},         {"max", band->max}};
  }
  return out;
}

std::string coverageCsv(const std::vector<CoverageBin>& bins, const CoverageBand* band) {
  std::string out = band ? "lower,upper,count,members,mean,sd,sem,ci95_low,ci95_high,min,max\n"
                         : "lower,upper,count\n";
  char line[512];
  for (std::size_t i = 0; i < bins.size(); ++i) {
    const auto& b = bins[i];
    if (band) {
      std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", b.lower,
                    b.upper, b.count, band->members, band->mean[i], band->sd[i], band->sem[i], band->ciLow[i],
                    band->ciHigh[i], band->min[i], band->max[i]);
    } else {
      std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", b.lower, b.upper, b.count);
    }
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
                     const std::vector<CoverageBin>& bins, std::string& error, const CoverageBand* band) {
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
  if (band && ok) {
    const hid_t group = H5Gcreate2(file, "/ensemble", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ok = group >= 0;
    if (ok) {
      const hid_t scalar = H5Screate(H5S_SCALAR);
      const long long members = band->members;
      const hid_t attr = H5Acreate2(group, "members", H5T_STD_I64LE, scalar, H5P_DEFAULT, H5P_DEFAULT);
      ok = attr >= 0 && H5Awrite(attr, H5T_NATIVE_LLONG, &members) >= 0;
      if (attr >= 0) H5Aclose(attr);
      H5Sclose(scalar);
      H5Gclose(group);
    }
    const std::pair<const char*, const std::vector<double>*> sets[] = {
        {"/ensemble/mean", &band->mean},         {"/ensemble/sd", &band->sd},   {"/ensemble/sem", &band->sem},
        {"/ensemble/ci95_low", &band->ciLow},    {"/ensemble/ci95_high", &band->ciHigh},
        {"/ensemble/min", &band->min},           {"/ensemble/max", &band->max}};
    for (const auto& [name, values] : sets) ok = ok && writeDataset(file, name, *values);
  }
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
