#pragma once
// Apparatus specs with the paper's values (docs/geometry.md) shared by the geometry tests.

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/Errors.hpp"
#include "scene/Scene.hpp"

namespace rcfd::test {

/// ProCell 5: width 0.25 m, depth 0.2 m, prism angle 60 deg (the paper); inlet 20 mm and height 0.6 m
/// (our choice); optionally the draft plates: 60 mm high, 45 mm apart (the paper), 2 mm thick and
/// 35 mm above y = 0 (10 mm clear above the V beneath them; docs/geometry.md).
inline ApparatusSpec procellSpec(bool plates) {
  ApparatusSpec a;
  a.type = ApparatusSpec::Type::PrismaticSpoutedBed;
  a.width = 0.25;
  a.depth = 0.2;
  a.height = 0.6;
  a.prism_angle_deg = 60.0;
  a.inlet_width = 0.02;
  if (plates) {
    DraftPlatesSpec p;
    p.height = 0.06;
    p.gap = 0.045;
    p.elevation = 0.035;
    p.thickness = 0.002;
    a.draft_plates = p;
  }
  return a;
}

inline ApparatusSpec boxSpec(double lx, double ly, double lz, bool outletTop) {
  ApparatusSpec a;
  a.type = ApparatusSpec::Type::Box;
  a.size = Vec3(lx, ly, lz);
  a.box_outlet_top = outletTop;
  return a;
}

/// Height where the paper's V walls meet the vertical walls: 0.115 tan(60 deg).
inline double procellYv() { return 0.115 * std::tan(std::numbers::pi / 3.0); }

/// The JSON pointers of the violations an InputError carries (empty if `f` does not throw one).
template <class F>
std::vector<std::string> violationPointers(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    std::vector<std::string> out;
    for (const auto& v : e.violations()) out.push_back(v.pointer);
    return out;
  }
  return {};
}

}  // namespace rcfd::test
