#pragma once
/// \file FrameInterpolation.hpp
/// What the tracers see between two frames when dt < dt_rec, the scene's rcfd.frame_interpolation, and
/// between cell centres, rcfd.velocity_interpolation: a table of names each (the schema's enums are
/// checked against them). A frame is held over its whole interval
/// by default. Blending two frames shows a structure that moved between them as two weaker ones, and
/// the tracers in either move slower than the particles did: on the dilute jet sampled at 50 Hz,
/// spray-zone stays 18 % long blended against 10 % held (docs/accuracy.md, "Between frames").

#include <array>

#include "core/Registry.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

enum class FrameInterpolation { Hold, Linear };

inline constexpr std::array<NamedValue<FrameInterpolation>, 2> kFrameInterpolations{{
    {"hold", FrameInterpolation::Hold, "each frame over its whole interval, as at dt = dt_rec"},
    {"linear", FrameInterpolation::Linear, "the two frames of the interval blended linearly in time"},
}};

/// The scene's rule; InputError at /rcfd/frame_interpolation with the valid names for an unknown one.
inline FrameInterpolation frameInterpolation(const Scene& scene) {
  return parseNamedValue(kFrameInterpolations, scene.rcfd.frame_interpolation, "scene", "/rcfd/frame_interpolation");
}

/// What the tracers see between cell centres, the scene's rcfd.velocity_interpolation. A cell-centre
/// sample is the cell's u_P^rec either way. Between a dense slow cell and a dilute fast one, the
/// trilinear velocity moves the tracers there at the mean of the two speeds, so they carry more volume
/// than the particles' flux alpha_P u_P does (a dense layer over a dilute fall drains); mass-weighted,
/// u = interp(w u_P) / interp(w) with w = alpha_P^rec + kMassWeightFloor, the tracers' flux is the
/// interpolated particle flux (docs/calibration.md, "Velocity between cell centres").
enum class VelocityInterpolation { Trilinear, MassWeighted };

inline constexpr std::array<NamedValue<VelocityInterpolation>, 2> kVelocityInterpolations{{
    {"trilinear", VelocityInterpolation::Trilinear, "u_P^rec interpolated trilinearly between cell centres"},
    {"mass_weighted", VelocityInterpolation::MassWeighted,
     "alpha_P^rec u_P^rec and alpha_P^rec interpolated alike, the velocity their ratio: the particle flux"},
}};

/// The weight floor of the mass-weighted velocity: cells without particles count as holding this much,
/// so that where none of the 8 corners holds any the velocity is the trilinear one (no 0 / 0). Below
/// every alpha_P that carries particles (a parcel in a cell is a few per cent); the draft-plates slice's
/// spray-zone figures change by under 5 % between 1e-3 and 3e-2.
inline constexpr float kMassWeightFloor = 1e-3f;

/// The scene's rule; InputError at /rcfd/velocity_interpolation with the valid names for an unknown one.
inline VelocityInterpolation velocityInterpolation(const Scene& scene) {
  return parseNamedValue(kVelocityInterpolations, scene.rcfd.velocity_interpolation, "scene",
                         "/rcfd/velocity_interpolation");
}

}  // namespace rcfd
