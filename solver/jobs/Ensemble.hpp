#pragma once
/// \file Ensemble.hpp
/// A spray job's ensemble (`"ensemble": K` in the job file): K realisations of the run, member k with
/// seed ensembleSeeds(seed, K)[k], its own recurrence path and tracer placement, all on the one
/// database in memory. Every member is exactly the spray job run with its seed; this file turns the
/// members' summaries and result files into the job's: the keys of summary.json outside `ensemble` and
/// the root of result.h5 are member 0's (the job's own seed: what the job without `ensemble` writes),
/// `ensemble` and `/ensemble` give each statistic's mean and spread over the members
/// (docs/formats.md, "Spray job output").

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/Hdf5.hpp"

namespace rcfd {

/// Largest number of members of an ensemble (the job schema's bound).
inline constexpr int kMaxEnsembleMembers = 64;

/// Seeds of the members: member 0 the job's seed, member k >= 1 a SplitMix64 mix of the seed and k,
/// below 2^53 (exact in any JSON reader, usable as a job's `seed` to rerun that member alone) and
/// distinct from the members before it. The same (seed, k) always gives the same seed, whatever K.
std::vector<std::uint64_t> ensembleSeeds(std::uint64_t jobSeed, int members);

/// Member k's name in the result tree and its directory under DIR/members/: two digits or more ("07").
std::string ensembleMemberName(std::size_t k);

/// JSON pointers into a spray job's summary of the statistics the ensemble reports as mean and
/// spread (those present as numbers in every member's summary).
const std::vector<std::string>& ensembleStatisticPointers();

/// The `ensemble` block of summary.json from the members' summaries (member order): "members",
/// "seeds", "interval", the spread (analysis::toJson(Spread)) of each statistic at its own pointer
/// (e.g. ensemble.coverage.median) and the coverage histogram's band per bin.
nlohmann::json ensembleSummary(const std::vector<nlohmann::json>& members, const std::vector<std::uint64_t>& seeds);

/// Adds /ensemble to a result.h5 whose root holds member 0's results: the members' seeds, every
/// statistic's member values, the coverage histogram's per-member counts and band, and each member's
/// result tree (its result.h5 without /scene) with its summary under /ensemble/members/NN (member 0's
/// hard-linked to the root's datasets).
void writeEnsembleResults(h5::File& out, const nlohmann::json& ensemble, const std::vector<std::string>& memberFiles,
                          const std::vector<nlohmann::json>& memberSummaries);

/// coverage.svg for an ensemble: the members' mean fraction of tracers per coverage bin, the 95 %
/// interval of that mean as a band and the members' range as whiskers; returns the file name.
std::string writeEnsembleCoverageFigure(const nlohmann::json& ensemble, double simTime, const std::string& outDir);

}  // namespace rcfd
