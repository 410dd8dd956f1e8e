#pragma once
/// \file Scene.hpp
/// The typed form of a scene (schemas/scene.schema.json): apparatus, grid, gas, particles, process,
/// spray, dem, rcfd, effects, probes, outputs. SI units throughout (m, s, kg, m3/s, Pa); angles are the
/// only exception and carry `_deg` in their names. Defaults here equal the schema's "default" values
/// (a test checks this) and are the paper's values where the paper gives one (docs/parameters.md).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace rcfd {

using Vec3 = Eigen::Vector3d;

/// Two vertical plates spanning the depth, left and right of the spout (Pietsch et al. 2017).
struct DraftPlatesSpec {
  double height = 0.06;      ///< vertical extent [m]
  double gap = 0.045;        ///< clear distance between the plates' inner faces [m]
  /// Height of the plates' lower edge above the inlet exit y = 0 [m]. The paper's "10 mm above the mid
  /// profile" is kept as 10 mm of clearance above the V-bottom beneath the plates (docs/parameters.md).
  double elevation = 0.035;
  double thickness = 0.002;  ///< plate thickness [m] (the paper is silent; docs/parameters.md)
};

/// The apparatus. Coordinates: x lateral (0 on the symmetry plane), y up (0 at the inlet slot exit),
/// z along the depth from 0 to `depth`.
struct ApparatusSpec {
  enum class Type { PrismaticSpoutedBed, Box };
  Type type = Type::PrismaticSpoutedBed;

  // prismatic_spouted_bed
  double width = 0.25;            ///< distance between the vertical side walls [m]
  double depth = 0.2;             ///< extent along z [m]
  double height = 0.6;            ///< chamber height above y = 0; the outlet is the top face [m]
  double prism_angle_deg = 60.0;  ///< inclination of the V-bottom walls against the horizontal [deg]
  double inlet_width = 0.02;      ///< width of the gas inlet slot at y = 0 (the bottom of the V) [m]
  std::optional<DraftPlatesSpec> draft_plates;

  // box: x in [-size.x/2, size.x/2], y in [0, size.y], z in [0, size.z]; all faces are walls unless
  // `box_outlet_top` makes the top face an outlet.
  Vec3 size = Vec3(0.1, 0.1, 0.1);
  bool box_outlet_top = false;
};

/// Uniform Cartesian grid over the apparatus's bounding box.
struct GridSpec {
  Vec3 cell_size = Vec3(0.005, 0.005, 0.005);  ///< [m]; the scene may give one number for all three
};

struct GasSpec {
  double density = 1.225;                ///< rho_G [kg/m3]
  double kinematic_viscosity = 1.5e-5;   ///< nu_G [m2/s]
  double cfl = 0.8;                      ///< largest Courant number of the adaptive gas time step [-]
  double max_time_step = 2.5e-5;         ///< upper bound of dt_CFD [s]
  double pressure_tolerance = 1e-8;      ///< relative residual of the pressure solver [-]
  /// Preconditioner of the pressure CG, a name of gas::PreconditionerRegistry
  /// ("mg": aggregation multigrid, "ic": incomplete Cholesky, "jacobi").
  std::string pressure_preconditioner = "mg";
  double smoothing_length = 5.4e-3;      ///< L_smooth of Eq. (3), about three particle diameters [m]
  /// Drag law F(eps, Re) of the coupling, a name of coupling::DragModelRegistry ("beetstra",
  /// "gidaspow", "wen_yu").
  std::string drag_model = "beetstra";
};

struct ParticleSpec {
  double diameter = 1.8e-3;         ///< d_P [m]
  double density = 1040.0;          ///< rho_P [kg/m3]
  double youngs_modulus = 5e6;      ///< Y [Pa], particles and walls alike
  double poisson_ratio = 0.25;      ///< [-]
};

struct ProcessSpec {
  double gas_flow_rate = 230.0 / 3600.0;       ///< process air through the inlet slot [m3/s]
  double atomisation_flow_rate = 5.0 / 3600.0; ///< nozzle air [m3/s]
  double bed_mass = 1.5;                       ///< M_P [kg]
};

/// A cone with its apex at `apex`, axis +y, cut to y_min <= y <= y_max (the paper's Fig. 2).
struct SprayZoneSpec {
  Vec3 apex = Vec3(0.0, 0.0, 0.1);  ///< [m]
  double half_angle_deg = 17.0;     ///< [deg]
  double y_min = 0.02;              ///< [m]
  double y_max = 0.1;               ///< [m]
  /// Only the part of the cone a straight line from the apex reaches without crossing a draft plate:
  /// the region the spray sees, not the bed behind or on top of a plate.
  bool line_of_sight = false;
};

struct SpraySpec {
  Vec3 nozzle_position = Vec3(0.0, 0.0, 0.1);  ///< nozzle tip [m], pointing up (+y)
  double nozzle_diameter = 0.004;              ///< outer diameter of the nozzle head [m]
  double cone_half_angle_deg = 17.0;           ///< spray cone half-angle [deg]
  double mass_rate = 0.3 / 3600.0;             ///< M_spray [kg/s]
  double droplet_diameter = 40e-6;             ///< d_D [m]
  double droplet_density = 1000.0;             ///< rho_D [kg/m3]
  double parcels_per_s = 1e5;                  ///< parcel injection rate [1/s]
  std::string deposition_model = "exponential";  ///< "exponential" or "linear_clipped" (Eq. 11)
  SprayZoneSpec spray_zone;
};

struct ContactPair {
  double particle_particle = 0.0;
  double particle_wall = 0.0;
};

/// Settings of the built-in CFD-DEM and of the database job's sampling.
struct DemSpec {
  double coarse_graining = 1.0;            ///< cg: a parcel of diameter cg d_P stands for cg^3 particles
  double time_step = 1e-6;                 ///< dt_DEM [s]
  double max_rayleigh_fraction = 0.3;      ///< dt_DEM above this fraction of the Rayleigh time is refused
  double max_overlap_fraction = 0.003;     ///< warn when an overlap exceeds this fraction of the radius
  int coupling_interval = 25;              ///< DEM steps per gas step
  ContactPair restitution{0.9, 0.75};      ///< e_PP, e_PW
  ContactPair friction{0.5, 0.24};         ///< k_fr
  ContactPair rolling_friction{0.06, 0.05};///< k_rfr
  double settle_time = 0.5;                ///< DEM-only settling before the gas starts [s]
  double ramp_time = 0.2;                  ///< linear ramp of the gas flows from 0 to 1 after settling [s]
  double warmup = 3.0;                     ///< gas-on time at full flow before sampling starts [s]
  double sample_rate = 200.0;              ///< field sampling frequency, 1/dt_rec [Hz]
  double probe_rate = 1000.0;              ///< reference series (probes, pressure drop, holdup) [Hz]
  double sample_duration = 10.0;           ///< sampled period [s]
  double reference_duration = 10.0;        ///< period after sampling for reference statistics [s]
  /// alpha_P the frames record: "parcels" (the parcels' own kernel volume, whose velocity u_P is, so
  /// alpha_P u_P is their flux) or "coupling" (as the gas sees it, smoothed by Eq. (3) when enabled)
  std::string frame_alpha_p = "coupling";
};

struct PathSpec {
  std::string type = "paper";        ///< "paper", "markov" or "file"
  double min_sequence_fraction = 0.05;  ///< shortest sequence as a fraction of the frames (N/20)
  double max_sequence_fraction = 0.2;   ///< longest sequence as a fraction of the frames (N/5)
  int min_sequence_frames = 10;         ///< markov: shortest sequence [frames]
  int correlation_window = 20;          ///< markov: jump targets exclude frames this close [frames]
  std::string file;                     ///< "file": path of a predefined frame sequence
};

struct RcfdSpec {
  double dt = 5e-3;                 ///< tracer time step [s]; dt_rec by default
  long tracers = 472850;            ///< number of tracers N
  double d0 = 5e-4;                 ///< D0 of Eq. (10) [m2/s]
  double u_fluc_max = 1.0;          ///< cap of |u_fluc| [m/s]
  double free_flight_alpha = 0.02;  ///< free flight where alpha_P^rec is below this [-]
  double langevin_time = 0.3;       ///< longest memory T of langevin_velocity (the dilute limit) [s]
  std::string fluctuation_model = "lichtenegger_pirker";  ///< or "cfdem"
  double max_courant = 1.0;         ///< particle Courant number bound for sub-stepping [-]
  std::string integrator = "midpoint";  ///< Eq. (9) time integration: "midpoint" (2nd order) or "euler"
  /// Fields between two frames when dt < dt_rec: "hold" (each frame over its whole interval) or
  /// "linear" (the two frames blended)
  std::string frame_interpolation = "hold";
  /// u_P^rec between cell centres: "trilinear" or "mass_weighted" (the particle flux over alpha_P)
  std::string velocity_interpolation = "trilinear";
  long frame_cache_bytes = 0;       ///< 0: load all frames into RAM; else LRU cache size [bytes]
  PathSpec path;
};

struct ProbeSpec {
  std::string name;
  Vec3 position = Vec3::Zero();  ///< [m]
};

struct OutputSpec {
  int coverage_bins = 20;        ///< bins of the coverage histogram on [0, 1]
  int residence_time_bins = 40;  ///< bins of the residence-time histogram
  bool svg = true;               ///< write SVG figures beside result.h5
};

/// A complete, validated scene.
struct Scene {
  std::string name;
  std::string description;
  ApparatusSpec apparatus;
  GridSpec grid;
  GasSpec gas;
  ParticleSpec particles;
  ProcessSpec process;
  SpraySpec spray;
  DemSpec dem;
  RcfdSpec rcfd;
  std::vector<std::string> effects;
  std::vector<ProbeSpec> probes;
  OutputSpec outputs;
  std::string source_json;  ///< the scene as given (stored with databases and results)

  bool hasEffect(const std::string& name) const;
};

}  // namespace rcfd
