#pragma once
/// \file CoverageExport.hpp
/// The stored coverage histogram of a spray job as JSON, CSV or HDF5 (/edges [bins+1],
/// /counts [bins], float64), optionally with adjacent bins merged.

#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "JobStore.hpp"

namespace rcfd::server {

/// The HDF5 library of Debian 12 is not built thread-safe: every HDF5 call in the server holds this.
std::mutex& hdf5Mutex();

/// Merges groups of stored.size()/n adjacent bins into n bins (n divides stored.size()).
std::vector<CoverageBin> mergeBins(const std::vector<CoverageBin>& stored, std::size_t n);
/// "1, 2, 4, ..." : the bin counts mergeBins accepts.
std::string divisorsText(std::size_t n);

nlohmann::json coverageJson(const std::string& jobId, const std::vector<CoverageBin>& bins);
/// "lower,upper,count" rows, numbers printed exactly (17 significant digits).
std::string coverageCsv(const std::vector<CoverageBin>& bins);
/// Writes the file atomically (temporary name, then rename); false with `error` set on failure.
bool writeCoverageH5(const std::filesystem::path& path, const std::string& jobId,
                     const std::vector<CoverageBin>& bins, std::string& error);

}  // namespace rcfd::server
