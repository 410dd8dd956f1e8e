#pragma once
/// \file OpenFoamCase.hpp
/// The layout of an OpenFOAM case directory as rcfd imports it: its parts (the case itself when it is
/// reconstructed, else processor0, processor1, ... of a decomposed case, each with its own mesh and
/// fields, mapped one after the other), its written times, its Lagrangian cloud and which files give
/// the gas velocity and the particle phase.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rcfd::openfoam {

struct WrittenTime {
  std::string name;  ///< the directory name as written ("0.25")
  double value = 0;  ///< [s]
};

/// Times to import: [first, last] inclusive; without a range, every written time but 0 (the initial
/// conditions, as OpenFOAM's -noZero).
struct TimeRange {
  std::optional<double> first, last;
  /// Parses "A:B", "A:" or ":B" [s]; rcfd::InputError naming `option` otherwise.
  static TimeRange parse(const std::string& text, const std::string& option);
  bool contains(double t) const;
  bool given() const { return first || last; }
};

/// Where the particle phase comes from.
enum class ParticleSource { Lagrangian, EulerianFraction, EulerianVoidFraction };

struct OpenFoamCase {
  std::filesystem::path root;
  std::vector<std::filesystem::path> parts;  ///< root, or root/processorN in processor order
  bool decomposed = false;
  std::vector<WrittenTime> times;            ///< selected times, increasing
  std::string cloud;                         ///< Lagrangian cloud name (empty: Eulerian particle phase)
  ParticleSource particleSource = ParticleSource::Lagrangian;
  std::string gasVelocityField;              ///< e.g. U.air
  std::string particleFractionField;         ///< Eulerian: alpha.particles or voidfraction
  std::string particleVelocityField;         ///< Eulerian: U.particles or Us
  std::string pressureField;                 ///< the gas pressure, p (empty: the case writes none)

  /// Finds parts, times, cloud and fields. `cloudName` picks one of several clouds (empty: the only
  /// one). rcfd::InputError naming the directory or file when the case has no mesh, no selected time,
  /// several clouds and no choice, or none of the accepted field names.
  static OpenFoamCase open(const std::filesystem::path& root, const TimeRange& range, const std::string& cloudName = "");

  /// A time directory of part p.
  std::filesystem::path timeDir(std::size_t part, const WrittenTime& t) const { return parts[part] / t.name; }
};

/// Accepted names, in the order looked for (docs/import.md).
inline const std::vector<std::string> kGasVelocityNames = {"U.air", "U.gas", "U.continuous", "U"};
inline const std::vector<std::string> kParticleFractionNames = {"alpha.particles", "alpha.solid", "alpha.solids",
                                                                "alpha.particle"};
inline const std::vector<std::string> kVoidFractionNames = {"voidfraction"};
inline const std::vector<std::string> kPressureNames = {"p"};
inline const std::vector<std::string> kParticleVelocityNames = {"U.particles", "U.solid", "U.solids", "U.particle",
                                                                "Us"};

}  // namespace rcfd::openfoam
