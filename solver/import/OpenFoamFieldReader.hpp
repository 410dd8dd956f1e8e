#pragma once
/// \file OpenFoamFieldReader.hpp
/// OpenFOAM field files as arrays: the internalField of a volScalarField / volVectorField, and the
/// per-parcel files of a Lagrangian cloud (lagrangian/<cloud>/positions, U, d, nParticle, origId,
/// origProcId). ASCII or binary, plain or .gz (FoamFile.hpp).

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace rcfd::openfoam {

/// The internalField of a vol field file, `components` values per cell (1 scalar, 3 vector): a
/// `uniform` value repeated over `cellCount` cells or a `nonuniform List<...>` of exactly `cellCount`
/// items. rcfd::InputError naming the file and `internalField` otherwise.
std::vector<double> readInternalField(const std::filesystem::path& file, int components, std::int64_t cellCount);

/// SI exponents of a field's `dimensions` entry: [kg m s K mol A cd].
using Dimensions = std::array<double, 7>;

/// The same with the file's `dimensions` entry (5 or 7 exponents; the missing ones 0) in `dimensions`.
std::vector<double> readInternalField(const std::filesystem::path& file, int components, std::int64_t cellCount,
                                      Dimensions& dimensions);

/// The parcels of one cloud at one time, in file order.
struct CloudParcels {
  std::vector<double> position;    ///< xyz per parcel [m]
  std::vector<double> velocity;    ///< xyz per parcel [m/s] (file U)
  std::vector<double> diameter;    ///< [m] (file d)
  std::vector<double> nParticle;   ///< real particles per parcel [-] (file nParticle; 1 when absent)
  std::vector<std::int64_t> origId;      ///< identity within origProcId (file origId; empty when absent)
  std::vector<std::int64_t> origProcId;  ///< processor the parcel was created on (empty when absent)
  std::size_t size() const { return diameter.size(); }
  bool hasIdentities() const { return !origId.empty(); }
};

/// Reads lagrangian/<cloud>/ of one time. `positions` must be OpenFOAM's legacy form, `(x y z) celli`
/// per parcel (ASCII, or the binary record of 3 scalars and a label); a cloud holding only the
/// barycentric `coordinates` file is refused with the fix. `U` and `d` are required; `nParticle`,
/// `origId` and `origProcId` optional. Every file must list as many parcels as `positions`.
CloudParcels readCloud(const std::filesystem::path& cloudDir);

}  // namespace rcfd::openfoam
