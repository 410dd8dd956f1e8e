#pragma once
/// \file TracerIntegrator.hpp
/// The time integration of Eq. (9), the scene's rcfd.integrator: one table of names (the schema's enum
/// is checked against it), parsed where the motion effects are built. A switch in the motion kernel,
/// not a model object: both rules share the kernel's sampling and sub-stepping.

#include <array>

#include "core/Registry.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

enum class TracerIntegrator { Midpoint, Euler };

inline constexpr std::array<NamedValue<TracerIntegrator>, 2> kTracerIntegrators{{
    {"midpoint", TracerIntegrator::Midpoint, "midpoint rule: 2nd order, two field samples per sub-step"},
    {"euler", TracerIntegrator::Euler, "explicit Euler: 1st order, one field sample per sub-step"},
}};

/// The scene's integrator; InputError at /rcfd/integrator with the valid names for an unknown one.
inline TracerIntegrator tracerIntegrator(const Scene& scene) {
  return parseNamedValue(kTracerIntegrators, scene.rcfd.integrator, "scene", "/rcfd/integrator");
}

}  // namespace rcfd
