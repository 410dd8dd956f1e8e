#pragma once
/// \file VelocityCompletion.hpp
/// A frame's particle velocity where it has no particle to take it from.
///
/// u_P of a cell is the mean velocity of the particle volume in it; where a frame holds none, the
/// value carries no information (a CFD-DEM or MPPIC export writes 0 there). The tracers interpolate
/// u_P trilinearly from the eight cells around them, so at the edge of a dilute jet, whose cells are
/// empty in one frame and occupied in the next, such a 0 slows every tracer near it, where the
/// particles shot through: the spray-zone stays come out long and the crossings rare. Completing a
/// cell gives it the velocity of the particle volume next to it: the mean of its 26 neighbours that
/// hold velocity, weighted by their particle volume alpha_P phi. The velocity spread is completed
/// the same way, so that up_fraction u_p_up + (1 - up_fraction) u_p_down = u_p still holds.
///
/// Two places use it: the database reader completes the cells without particle volume
/// (alpha_P = 0) of every frame it serves, whoever wrote the file (one layer: what a trilinear stencil
/// touching an occupied cell reaches); the database job completes, before writing, the cells that
/// only the smoothing of Eq. (3) gave particle volume, layer by layer outward.

#include <cstdint>
#include <vector>

#include "fields/FieldDatabase.hpp"

namespace rcfd {

/// Completes u_P (and the velocity spread, when the frame has it) of the open cells (phi > 0) with
/// holdsVelocity == 0 that touch one with holdsVelocity != 0 and alpha_P > 0, for up to `layers`
/// layers: a completed cell with alpha_P > 0 passes its velocity on to the next layer. The open cells
/// without velocity out of reach get 0; cells that hold velocity and solid cells are left as they
/// are. Returns the number of cells completed.
std::int64_t completeParticleVelocity(const CartesianGrid& grid, const std::vector<float>& openFraction,
                                      std::vector<char> holdsVelocity, FieldFrame& frame, int layers);

/// holdsVelocity of the reader: the cells with alpha_P > 0.
std::vector<char> cellsWithParticleVolume(const FieldFrame& frame);

}  // namespace rcfd
