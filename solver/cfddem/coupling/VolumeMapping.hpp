#pragma once
/// \file VolumeMapping.hpp
/// Particle volume to the gas grid and gas fields back to the particles with one kernel: trilinear
/// (cloud-in-cell) weights on the eight cell centres around a parcel, each multiplied by the cell's
/// open volume fraction and renormalised over the open cells. Smooth when a cell is only ~1.4 parcel
/// diameters (quick.json), exact in the total volume (the weights of a parcel sum to one), and never
/// puts volume into a closed cell. The same weights interpolate cell fields to the parcel, so what a
/// parcel takes from a cell is what the cell gives (momentum exchange, docs/physics.md "Coupling").
/// Walls thinner than a cell (baffles, geometry/ThinWalls.hpp) cut the kernel: a cell centre that the
/// parcel's own cell reaches only through a baffle face gets no weight, so no volume crosses a plate;
/// a parcel in the strip between a plate and its baffle face counts from the cell across the face.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "cfddem/DemParticles.hpp"
#include "geometry/CartesianGrid.hpp"
#include "geometry/ThinWalls.hpp"

namespace rcfd::coupling {

/// The cells a parcel maps to and their weights (sum 1 over `count` entries).
struct KernelWeights {
  std::array<std::int32_t, 8> cell{};
  std::array<double, 8> w{};
  int count = 0;
};

/// Below these sizes an OpenMP team costs the coupling's loops more than it saves.
inline constexpr long kParallelParcels = 4096;
inline constexpr long kParallelCells = 8192;

/// The kernel weights regrouped by cell: for every cell the parcels whose weights point into it, with
/// those weights, in parcel order. A sum over a cell's entries adds the parcels' contributions in the
/// order a serial scatter over the parcels does, so a gather parallel over the cells gives the serial
/// scatter's bits for any number of threads.
struct CellContributions {
  std::vector<std::int32_t> start;   ///< entries of cell c: [start[c], start[c + 1])
  std::vector<std::int32_t> parcel;  ///< per entry: the parcel's index
  std::vector<double> weight;        ///< per entry: the parcel's weight in the cell
};

/// Over-packing limit: alpha_P of a cell's open volume above this after mapping (and smoothing) is
/// moved to the neighbouring open cells (VolumeMapping::redistributeExcess). Above random close
/// packing (0.64) so a resolved dense bed is untouched; mapped peaks near walls beyond it are a kernel
/// artefact, not a physical packing.
inline constexpr double kMaxParticleFraction = 0.7;

class VolumeMapping {
 public:
  /// openFraction per cell [-]; usable marks the cells that may receive volume (open and, with a gas
  /// solver, connected to the outlet); baffles: faces no weight and no excess volume may cross.
  VolumeMapping(const CartesianGrid& grid, std::vector<double> openFraction, std::vector<char> usable,
                BaffleFaces baffles = {});

  /// Weights of a point. A point whose eight neighbouring centres are all closed goes to the nearest
  /// usable cell of the 3x3x3 block around its own cell; RunError when there is none.
  KernelWeights weights(const Eigen::Vector3d& x) const;

  /// Weights of every parcel (index order).
  void weightsOf(const DemParticles& p, std::vector<KernelWeights>& out) const;

  /// Particle volume per cell [m3] (serial scatter in index order: deterministic). The plain path beside
  /// gatherVolume().
  void scatterVolume(const DemParticles& p, const std::vector<KernelWeights>& w, std::vector<double>& volume) const;
  /// The weights by cell (a counting sort, parallel over chunks of parcels; the result does not depend on
  /// the chunks).
  void contributionsOf(const std::vector<KernelWeights>& w, CellContributions& out) const;
  /// scatterVolume()'s result to the bit, gathered per cell in parallel.
  void gatherVolume(const DemParticles& p, const CellContributions& c, std::vector<double>& volume) const;

  /// alpha_P of the open volume from a volume per cell [-] (0 in unusable cells).
  std::vector<double> fractionOf(const std::vector<double>& volume) const;

  /// Moves particle volume out of cells above maxFraction of their open volume into their usable face
  /// neighbours not behind a baffle (in proportion to the neighbours' open volume), repeated until no cell is above the
  /// limit (to a relative 1e-9) or maxSweeps; exactly conservative. Returns the number of cells that gave volume.
  long redistributeExcess(std::vector<double>& volume, double maxFraction = kMaxParticleFraction,
                          int maxSweeps = 1000) const;

  /// Volume-weighted mean parcel velocity per cell, zero where a cell holds no particle volume [m/s].
  std::vector<Eigen::Vector3d> meanVelocity(const DemParticles& p, const std::vector<KernelWeights>& w) const;

  /// What the mean velocity of a cell's particle volume leaves out, with the weights of meanVelocity():
  /// the share of the volume moving up (v_y > 0), the mean velocity of the upward and of the other
  /// volume (the cell's mean where a part holds no volume, zero in an empty cell), and the variance of
  /// each velocity component about the mean interpolated to each parcel with its weights (so a linear
  /// shear across the kernel adds nothing). upFraction u_up + (1 - upFraction) u_down = mean to
  /// round-off.
  struct VelocitySpread {
    std::vector<Eigen::Vector3d> mean, up, down, variance;
    std::vector<double> upFraction;
  };
  VelocitySpread velocitySpread(const DemParticles& p, const std::vector<KernelWeights>& w) const;

  /// Interpolates a cell field to a point with weights w.
  template <class T>
  static T interpolate(const std::vector<T>& field, const KernelWeights& w) {
    T s = w.w[0] * field[std::size_t(w.cell[0])];
    for (int k = 1; k < w.count; ++k) s += w.w[std::size_t(k)] * field[std::size_t(w.cell[std::size_t(k)])];
    return s;
  }

  const CartesianGrid& grid() const { return grid_; }
  const std::vector<double>& openFraction() const { return phi_; }
  const std::vector<char>& usable() const { return usable_; }
  const BaffleFaces& baffles() const { return baffles_; }
  /// Open volume of cell c, V phi_c [m3].
  double openVolume(std::size_t c) const { return grid_.cellVolume() * phi_[c]; }

 private:
  /// Whether cell `to` is reached from cell `from` (indices differing by at most one per axis) by a
  /// path of face steps, one per differing axis in some order, none through a closing baffle face.
  bool reachable(const std::array<int, 3>& from, const std::array<int, 3>& to) const;

  CartesianGrid grid_;
  std::vector<double> phi_;
  std::vector<char> usable_;
  BaffleFaces baffles_;
};

/// Particle volume of parcel i [m3].
inline double parcelVolume(const DemParticles& p, std::size_t i) {
  return 4.0 / 3.0 * 3.14159265358979323846 * p.radius[i] * p.radius[i] * p.radius[i];
}

}  // namespace rcfd::coupling
