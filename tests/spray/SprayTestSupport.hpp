#pragma once
// A box with a nozzle at the bottom centre blowing up through a bed: the analytic stage for spray tests.
#include "../tracers/TracerTestSupport.hpp"

namespace rcfd::test {

/// Box 0.1 x 0.2 x 0.04 m, 1 cm cells, nozzle at (0, 0.005, 0.02); the gas rises at `gasSpeed`, the
/// particles are at rest with alpha_P^rec = `alpha` below y = bedHeight and 0 above.
inline Scene sprayBoxScene(long tracers, double alpha, double bedHeight = 0.2) {
  Scene s = boxScene({0.1, 0.2, 0.04}, 0.01, tracers, 0.005,
                     {"transport", "walls", "tracer_volume_fraction", "spray", "deposition", "coverage",
                      "deposition_maps"},
                     alpha * bedHeight / 0.2);
  s.apparatus.box_outlet_top = true;
  s.spray.nozzle_position = Vec3(0.0, 0.005, 0.02);
  s.spray.nozzle_diameter = 0.002;
  s.spray.parcels_per_s = 2000;  // 10 parcels per step
  s.spray.spray_zone.apex = Vec3(0.0, 0.005, 0.02);
  s.spray.spray_zone.y_min = 0.01;
  s.spray.spray_zone.y_max = 0.1;
  return s;
}

inline std::shared_ptr<FieldDatabase> sprayBoxDatabase(const Scene& s, double alpha, double bedHeight,
                                                       double gasSpeed, int frames = 6) {
  const CartesianGrid grid = gridOf(s);
  return database(s, frames, s.rcfd.dt, [=](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const double y = grid.cellCenter(ijk[0], ijk[1], ijk[2]).y();
      f.alpha_p[std::size_t(c)] = y < bedHeight ? float(alpha) : 0.0f;
      f.u_g[3 * c] = float(0.3 * std::sin(n + 30 * y));  // some sway so parcels reach the walls too
      f.u_g[3 * c + 1] = float(gasSpeed);
    }
  });
}

}  // namespace rcfd::test
