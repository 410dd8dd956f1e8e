#include "scene/SceneJson.hpp"

namespace rcfd {
namespace {

using nlohmann::json;

template <typename T>
void read(const json& object, const char* key, T& field) {
  if (auto it = object.find(key); it != object.end()) field = it->get<T>();
}

void readVec(const json& object, const char* key, Vec3& field) {
  if (auto it = object.find(key); it != object.end()) {
    field = Vec3((*it)[0].get<double>(), (*it)[1].get<double>(), (*it)[2].get<double>());
  }
}

void readPair(const json& object, const char* key, ContactPair& pair) {
  if (auto it = object.find(key); it != object.end()) {
    read(*it, "particle_particle", pair.particle_particle);
    read(*it, "particle_wall", pair.particle_wall);
  }
}

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }
json pair(const ContactPair& p) {
  return {{"particle_particle", p.particle_particle}, {"particle_wall", p.particle_wall}};
}

const json& section(const json& document, const char* key) {
  static const json empty = json::object();
  auto it = document.find(key);
  return it == document.end() ? empty : *it;
}

}  // namespace

Scene sceneFromJson(const json& document) {
  Scene s;
  read(document, "name", s.name);
  read(document, "description", s.description);

  const json& a = section(document, "apparatus");
  auto& app = s.apparatus;
  app.type = a.value("type", std::string("prismatic_spouted_bed")) == "box" ? ApparatusSpec::Type::Box
                                                                           : ApparatusSpec::Type::PrismaticSpoutedBed;
  read(a, "width", app.width);
  read(a, "depth", app.depth);
  read(a, "height", app.height);
  read(a, "prism_angle_deg", app.prism_angle_deg);
  read(a, "inlet_width", app.inlet_width);
  if (auto it = a.find("draft_plates"); it != a.end()) {
    DraftPlatesSpec plates;
    read(*it, "height", plates.height);
    read(*it, "gap", plates.gap);
    read(*it, "elevation", plates.elevation);
    read(*it, "thickness", plates.thickness);
    app.draft_plates = plates;
  }
  readVec(a, "size", app.size);
  read(a, "outlet_top", app.box_outlet_top);

  const json& g = section(document, "grid");
  if (auto it = g.find("cell_size"); it != g.end()) {
    if (it->is_number()) s.grid.cell_size = Vec3::Constant(it->get<double>());
    else readVec(g, "cell_size", s.grid.cell_size);
  }

  const json& gas = section(document, "gas");
  read(gas, "density", s.gas.density);
  read(gas, "kinematic_viscosity", s.gas.kinematic_viscosity);
  read(gas, "cfl", s.gas.cfl);
  read(gas, "max_time_step", s.gas.max_time_step);
  read(gas, "pressure_tolerance", s.gas.pressure_tolerance);
  read(gas, "pressure_preconditioner", s.gas.pressure_preconditioner);
  read(gas, "smoothing_length", s.gas.smoothing_length);
  read(gas, "drag_model", s.gas.drag_model);

  const json& p = section(document, "particles");
  read(p, "diameter", s.particles.diameter);
  read(p, "density", s.particles.density);
  read(p, "youngs_modulus", s.particles.youngs_modulus);
  read(p, "poisson_ratio", s.particles.poisson_ratio);

  const json& pr = section(document, "process");
  read(pr, "gas_flow_rate", s.process.gas_flow_rate);
  read(pr, "atomisation_flow_rate", s.process.atomisation_flow_rate);
  read(pr, "bed_mass", s.process.bed_mass);

  const json& sp = section(document, "spray");
  readVec(sp, "nozzle_position", s.spray.nozzle_position);
  read(sp, "nozzle_diameter", s.spray.nozzle_diameter);
  read(sp, "cone_half_angle_deg", s.spray.cone_half_angle_deg);
  read(sp, "mass_rate", s.spray.mass_rate);
  read(sp, "droplet_diameter", s.spray.droplet_diameter);
  read(sp, "droplet_density", s.spray.droplet_density);
  read(sp, "parcels_per_s", s.spray.parcels_per_s);
  read(sp, "deposition_model", s.spray.deposition_model);
  const json& zone = section(sp, "spray_zone");
  readVec(zone, "apex", s.spray.spray_zone.apex);
  read(zone, "half_angle_deg", s.spray.spray_zone.half_angle_deg);
  read(zone, "y_min", s.spray.spray_zone.y_min);
  read(zone, "y_max", s.spray.spray_zone.y_max);
  read(zone, "line_of_sight", s.spray.spray_zone.line_of_sight);

  const json& d = section(document, "dem");
  read(d, "coarse_graining", s.dem.coarse_graining);
  read(d, "time_step", s.dem.time_step);
  read(d, "max_rayleigh_fraction", s.dem.max_rayleigh_fraction);
  read(d, "max_overlap_fraction", s.dem.max_overlap_fraction);
  read(d, "coupling_interval", s.dem.coupling_interval);
  readPair(d, "restitution", s.dem.restitution);
  readPair(d, "friction", s.dem.friction);
  readPair(d, "rolling_friction", s.dem.rolling_friction);
  read(d, "settle_time", s.dem.settle_time);
  read(d, "ramp_time", s.dem.ramp_time);
  read(d, "warmup", s.dem.warmup);
  read(d, "sample_rate", s.dem.sample_rate);
  read(d, "probe_rate", s.dem.probe_rate);
  read(d, "sample_duration", s.dem.sample_duration);
  read(d, "reference_duration", s.dem.reference_duration);
  read(d, "frame_alpha_p", s.dem.frame_alpha_p);

  const json& r = section(document, "rcfd");
  read(r, "dt", s.rcfd.dt);
  read(r, "tracers", s.rcfd.tracers);
  read(r, "d0", s.rcfd.d0);
  read(r, "u_fluc_max", s.rcfd.u_fluc_max);
  read(r, "free_flight_alpha", s.rcfd.free_flight_alpha);
  read(r, "langevin_time", s.rcfd.langevin_time);
  read(r, "fluctuation_model", s.rcfd.fluctuation_model);
  read(r, "max_courant", s.rcfd.max_courant);
  read(r, "integrator", s.rcfd.integrator);
  read(r, "frame_interpolation", s.rcfd.frame_interpolation);
  read(r, "velocity_interpolation", s.rcfd.velocity_interpolation);
  read(r, "frame_cache_bytes", s.rcfd.frame_cache_bytes);
  const json& path = section(r, "path");
  read(path, "type", s.rcfd.path.type);
  read(path, "min_sequence_fraction", s.rcfd.path.min_sequence_fraction);
  read(path, "max_sequence_fraction", s.rcfd.path.max_sequence_fraction);
  read(path, "min_sequence_frames", s.rcfd.path.min_sequence_frames);
  read(path, "correlation_window", s.rcfd.path.correlation_window);
  read(path, "file", s.rcfd.path.file);

  read(document, "effects", s.effects);
  if (auto it = document.find("probes"); it != document.end()) {
    for (const auto& probe : *it) {
      ProbeSpec spec;
      read(probe, "name", spec.name);
      readVec(probe, "position", spec.position);
      s.probes.push_back(spec);
    }
  }

  const json& o = section(document, "outputs");
  read(o, "coverage_bins", s.outputs.coverage_bins);
  read(o, "residence_time_bins", s.outputs.residence_time_bins);
  read(o, "svg", s.outputs.svg);
  return s;
}

json sceneToJson(const Scene& s) {
  json doc = json::object();
  doc["name"] = s.name;
  doc["description"] = s.description;
  const auto& app = s.apparatus;
  if (app.type == ApparatusSpec::Type::Box) {
    doc["apparatus"] = {{"type", "box"}, {"size", vec(app.size)}, {"outlet_top", app.box_outlet_top}};
  } else {
    doc["apparatus"] = {{"type", "prismatic_spouted_bed"}, {"width", app.width}, {"depth", app.depth},
                        {"height", app.height}, {"prism_angle_deg", app.prism_angle_deg},
                        {"inlet_width", app.inlet_width}};
    if (app.draft_plates) {
      const auto& pl = *app.draft_plates;
      doc["apparatus"]["draft_plates"] = {{"height", pl.height}, {"gap", pl.gap},
                                          {"elevation", pl.elevation}, {"thickness", pl.thickness}};
    }
  }
  doc["grid"] = {{"cell_size", vec(s.grid.cell_size)}};
  doc["gas"] = {{"density", s.gas.density}, {"kinematic_viscosity", s.gas.kinematic_viscosity},
                {"cfl", s.gas.cfl}, {"max_time_step", s.gas.max_time_step},
                {"pressure_tolerance", s.gas.pressure_tolerance},
                {"pressure_preconditioner", s.gas.pressure_preconditioner},
                {"smoothing_length", s.gas.smoothing_length}, {"drag_model", s.gas.drag_model}};
  doc["particles"] = {{"diameter", s.particles.diameter}, {"density", s.particles.density},
                      {"youngs_modulus", s.particles.youngs_modulus},
                      {"poisson_ratio", s.particles.poisson_ratio}};
  doc["process"] = {{"gas_flow_rate", s.process.gas_flow_rate},
                    {"atomisation_flow_rate", s.process.atomisation_flow_rate},
                    {"bed_mass", s.process.bed_mass}};
  const auto& sp = s.spray;
  doc["spray"] = {{"nozzle_position", vec(sp.nozzle_position)}, {"nozzle_diameter", sp.nozzle_diameter},
                  {"cone_half_angle_deg", sp.cone_half_angle_deg}, {"mass_rate", sp.mass_rate},
                  {"droplet_diameter", sp.droplet_diameter}, {"droplet_density", sp.droplet_density},
                  {"parcels_per_s", sp.parcels_per_s}, {"deposition_model", sp.deposition_model},
                  {"spray_zone", {{"apex", vec(sp.spray_zone.apex)}, {"half_angle_deg", sp.spray_zone.half_angle_deg},
                                  {"y_min", sp.spray_zone.y_min}, {"y_max", sp.spray_zone.y_max},
                                  {"line_of_sight", sp.spray_zone.line_of_sight}}}};
  const auto& d = s.dem;
  doc["dem"] = {{"coarse_graining", d.coarse_graining}, {"time_step", d.time_step},
                {"max_rayleigh_fraction", d.max_rayleigh_fraction},
                {"max_overlap_fraction", d.max_overlap_fraction}, {"coupling_interval", d.coupling_interval},
                {"restitution", pair(d.restitution)}, {"friction", pair(d.friction)},
                {"rolling_friction", pair(d.rolling_friction)}, {"settle_time", d.settle_time},
                {"ramp_time", d.ramp_time}, {"warmup", d.warmup}, {"sample_rate", d.sample_rate},
                {"probe_rate", d.probe_rate}, {"sample_duration", d.sample_duration},
                {"reference_duration", d.reference_duration}, {"frame_alpha_p", d.frame_alpha_p}};
  const auto& r = s.rcfd;
  doc["rcfd"] = {{"dt", r.dt}, {"tracers", r.tracers}, {"d0", r.d0}, {"u_fluc_max", r.u_fluc_max},
                 {"free_flight_alpha", r.free_flight_alpha}, {"langevin_time", r.langevin_time}, {"fluctuation_model", r.fluctuation_model},
                 {"max_courant", r.max_courant}, {"integrator", r.integrator},
                 {"frame_interpolation", r.frame_interpolation},
                 {"velocity_interpolation", r.velocity_interpolation},
                 {"frame_cache_bytes", r.frame_cache_bytes},
                 {"path", {{"type", r.path.type}, {"min_sequence_fraction", r.path.min_sequence_fraction},
                           {"max_sequence_fraction", r.path.max_sequence_fraction},
                           {"min_sequence_frames", r.path.min_sequence_frames},
                           {"correlation_window", r.path.correlation_window}, {"file", r.path.file}}}};
  doc["effects"] = s.effects;
  doc["probes"] = json::array();
  for (const auto& probe : s.probes) doc["probes"].push_back({{"name", probe.name}, {"position", vec(probe.position)}});
  doc["outputs"] = {{"coverage_bins", s.outputs.coverage_bins},
                    {"residence_time_bins", s.outputs.residence_time_bins}, {"svg", s.outputs.svg}};
  return doc;
}

}  // namespace rcfd
