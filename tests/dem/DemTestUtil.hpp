#pragma once
// Shared set-ups of the DEM tests: a material, a box, a system.
#include <cmath>
#include <numbers>
#include <spdlog/spdlog.h>

#include "cfddem/DemSystem.hpp"

namespace rcfd::demtest {

inline DemMaterial material(double radius, double e_pp, double e_pw, double mu_pp = 0.0,
                            double mu_pw = 0.0, double mr_pp = 0.0, double mr_pw = 0.0,
                            double youngs = 1e7, double density = 1000.0, double nu = 0.25) {
  return DemMaterial::make(density, youngs, nu, radius, ContactPair{e_pp, e_pw},
                           ContactPair{mu_pp, mu_pw}, ContactPair{mr_pp, mr_pw});
}

/// Undamped Hertz contact duration 2.87 (m*^2 / (R* Y*^2 v))^(1/5) [s].
inline double hertzDuration(double m_eff, double r_eff, double y_eff, double v) {
  return 2.87 * std::pow(m_eff * m_eff / (r_eff * y_eff * y_eff * v), 0.2);
}

inline double sphereMass(const DemMaterial& m) {
  return 4.0 / 3.0 * std::numbers::pi * std::pow(m.particle_radius, 3) * m.density;
}

struct QuietLog {
  QuietLog() { spdlog::set_level(spdlog::level::warn); }
};

}  // namespace rcfd::demtest
