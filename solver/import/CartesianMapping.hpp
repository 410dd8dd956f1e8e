#pragma once
/// \file CartesianMapping.hpp
/// Maps what an OpenFOAM case holds onto the scene's Cartesian grid, one frame at a time:
///  - particle volume (a parcel's nParticle pi d^3 / 6, or an Eulerian cell's alpha_P V) goes whole to
///    the grid cell holding the parcel or the cell centre, so alpha_P = sum V_P / (V_cell phi) (of the
///    open volume, as rcfd's own mapping, docs/physics.md) and the total is conserved;
///  - u_P is the particle-volume-weighted mean velocity of what a cell received;
///  - u_G is the volume-weighted mean gas velocity of the OpenFOAM cells whose centres the cell holds.
/// What lands in a closed grid cell (phi = 0) or outside the grid goes to the nearest open cell (by
/// face steps through the grid). A cell given more particle volume than it has open volume passes the
/// excess to its open face neighbours with its velocity until none is over-full (alpha_P <= 1), so the
/// total stays the same. Open cells that no OpenFOAM cell centre fell into (a grid finer than the
/// mesh) take the mean u_G of their filled face neighbours, wave by wave.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "fields/FieldDatabase.hpp"
#include "geometry/CartesianGrid.hpp"

namespace rcfd::openfoam {

/// What one mapped frame needed beyond plain binning (summary.json of the import).
struct MappingCounts {
  std::int64_t redirected = 0;       ///< items placed in a closed cell or outside the grid, moved to an open one
  std::int64_t outsideGrid = 0;      ///< of which outside the grid's box
  std::int64_t overfullCells = 0;    ///< cells that passed particle volume on (alpha_P > 1)
  std::int64_t gasFilledCells = 0;   ///< open cells whose u_G came from neighbours
  double particleVolume = 0.0;       ///< total particle volume received [m3]
  double mappedParticleVolume = 0.0; ///< sum alpha_P V_cell phi of the frame as stored (float32) [m3]
};

class CartesianMapping {
 public:
  /// fluidFraction: open fraction phi of every grid cell (at least one > 0).
  CartesianMapping(const CartesianGrid& grid, std::vector<float> fluidFraction);

  /// The open cell that receives what lies at p; `outside` tells whether p was outside the grid box.
  std::int64_t receivingCell(const Eigen::Vector3d& p, bool* redirected = nullptr, bool* outside = nullptr) const;

  /// Record the particles' velocity spread in every frame (FieldFrame::up_fraction, u_p_up, u_p_down,
  /// u_p_variance), as the database job does for the tracer effects that read it.
  void recordVelocitySpread(bool on) { spread_ = on; }

  /// Starts a new frame (clears the sums).
  void beginFrame();
  void addParticles(const Eigen::Vector3d& at, double volume, const Eigen::Vector3d& velocity);
  void addGas(const Eigen::Vector3d& at, double volume, const Eigen::Vector3d& velocity);
  /// The frame: alpha_p, u_p, u_g, and the velocity spread when recorded; rcfd::InputError when the
  /// particle volume does not fit into the open volume at all.
  FieldFrame finishFrame(MappingCounts& counts);

  const CartesianGrid& grid() const { return grid_; }
  const std::vector<float>& fluidFraction() const { return fluid_; }

 private:
  void redistributeOverfull(MappingCounts& counts);
  void addVelocitySpread(FieldFrame& f) const;
  /// u_P of frame f trilinear between the centres of the open cells at p (the mean a tracer there moves
  /// with), the cell's own where no open neighbour holds particles.
  Eigen::Vector3d interpolatedMean(const FieldFrame& f, const Eigen::Vector3d& p, std::size_t cell) const;
  struct Received {
    Eigen::Vector3d at, velocity;
    double volume;
    std::size_t cell;
  };
  bool spread_ = false;
  std::vector<Received> received_particles_;  ///< this frame's particles, when the spread is recorded
  std::vector<std::array<std::int64_t, 6>> neighbours_;  ///< open face neighbours (-1: none)
  CartesianGrid grid_;
  std::vector<float> fluid_;
  std::vector<std::int64_t> nearestOpen_;  ///< per cell: itself if open, else the nearest open cell
  std::vector<double> particleVolume_, particleMomentum_, gasVolume_, gasMomentum_;
  std::int64_t redirected_ = 0, outside_ = 0;
  double received_ = 0.0;
};

}  // namespace rcfd::openfoam
