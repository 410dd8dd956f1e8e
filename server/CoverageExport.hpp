#pragma once
/// \file CoverageExport.hpp
/// The stored coverage histogram of a spray job as JSON, CSV or HDF5 (/edges [bins+1],
/// /counts [bins], float64), optionally with adjacent bins merged; for an ensemble with its band over
/// the members (docs/api.md).

#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
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

/// An ensemble's band per bin over its members (tracers per bin): mean, sample standard deviation,
/// standard error of the mean, its 95 % interval, smallest and largest member.
struct CoverageBand {
  int members = 0;
  std::vector<double> mean, sd, sem, ciLow, ciHigh, min, max;
};
/// The band of a spray job's summary in `bins` bins (merged like mergeBins) from its members' counts
/// (ensemble.coverage.histogram.member_counts); nothing for a job without an ensemble.
std::optional<CoverageBand> coverageBand(const nlohmann::json& summary, std::size_t bins);

/// `counts` are the stored histogram's (member 0's for an ensemble); a band adds "ensemble".
nlohmann::json coverageJson(const std::string& jobId, const std::vector<CoverageBin>& bins,
                            const CoverageBand* band = nullptr);
/// "lower,upper,count" rows (a band adds "members,mean,sd,sem,ci95_low,ci95_high,min,max"), numbers
/// printed exactly (17 significant digits).
std::string coverageCsv(const std::vector<CoverageBin>& bins, const CoverageBand* band = nullptr);
/// Writes the file atomically (temporary name, then rename); false with `error` set on failure. A
/// band adds /ensemble/{mean,sd,sem,ci95_low,ci95_high,min,max} and the attribute /ensemble@members.
bool writeCoverageH5(const std::filesystem::path& path, const std::string& jobId,
                     const std::vector<CoverageBin>& bins, std::string& error,
                     const CoverageBand* band = nullptr);

}  // namespace rcfd::server
