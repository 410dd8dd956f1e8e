#pragma once
/// \file SmallScenes.hpp
/// Scenes small enough for a whole job in a test through the real rcfd-solve binary.

#include <nlohmann/json.hpp>

namespace rcfd::test {

/// A DEM-only database job (no `gas`): 340 parcels of 3 mm settle in a 4 x 10 x 2 cm box of 5 mm cells
/// and are sampled as they lie, 10 frames at 200 Hz.
inline nlohmann::json demOnlyDatabaseScene() {
  return nlohmann::json::parse(R"({
    "name": "database-job-test",
    "apparatus": {"type": "box", "size": [0.04, 0.1, 0.02]},
    "grid": {"cell_size": 0.005},
    "gas": {},
    "particles": {"diameter": 0.003, "density": 1040.0},
    "process": {"bed_mass": 0.005},
    "spray": {"nozzle_position": [0.0, 0.002, 0.01], "nozzle_diameter": 0.002,
              "spray_zone": {"apex": [0.0, 0.0, 0.01], "half_angle_deg": 30, "y_min": 0.004, "y_max": 0.03}},
    "dem": {"time_step": 2e-5, "coupling_interval": 5, "settle_time": 0.15, "ramp_time": 0.0, "warmup": 0.01,
            "sample_rate": 200, "probe_rate": 1000, "sample_duration": 0.05, "reference_duration": 0.03},
    "probes": [{"name": "bed", "position": [0.0025, 0.0025, 0.0075]}, {"name": "above", "position": [0.0025, 0.08, 0.0075]}],
    "effects": ["rolling_friction"],
    "outputs": {"svg": true}
  })");
}

}  // namespace rcfd::test
