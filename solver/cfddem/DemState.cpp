// DemSystem checkpoints: every array that the next step reads, so that save -> load -> continue is
// bit-identical to continuing (DemSystem.hpp).

#include <string>

#include "cfddem/DemSystem.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "core/Vec3Packing.hpp"

namespace rcfd {
namespace {

template <class Int>
std::vector<std::int64_t> widen(const std::vector<Int>& v) {
  return std::vector<std::int64_t>(v.begin(), v.end());
}

template <class Int>
std::vector<Int> narrow(const std::vector<std::int64_t>& v) {
  return std::vector<Int>(v.begin(), v.end());
}

}  // namespace

void DemSystem::saveState(h5::File& file, const std::string& group) const {
  const DemParticles& p = particles_;
  file.createGroup(group);
  file.write(group + "/x", flattenVec3(p.x));
  file.write(group + "/v", flattenVec3(p.v));
  file.write(group + "/omega", flattenVec3(p.omega));
  file.write(group + "/force", flattenVec3(p.force));
  file.write(group + "/torque", flattenVec3(p.torque));
  file.write(group + "/fluid_force", flattenVec3(p.fluid_force));
  file.write(group + "/radius", p.radius);
  file.write(group + "/mass", p.mass);
  file.write(group + "/inv_mass", p.inv_mass);
  file.write(group + "/inv_inertia", p.inv_inertia);
  file.write(group + "/id", widen(p.id));
  const std::string l = group + "/list";
  file.createGroup(l);
  file.write(l + "/row_start", widen(list_.row_start));
  file.write(l + "/j", widen(list_.j));
  file.write(l + "/shear", flattenVec3(list_.shear));
  file.write(l + "/col_start", widen(list_.col_start));
  file.write(l + "/col_pair", widen(list_.col_pair));
  file.write(l + "/wall_start", widen(list_.wall_start));
  file.write(l + "/wall_id", widen(list_.wall_id));
  file.write(l + "/x_at_build", flattenVec3(list_.positionsAtBuild()));
  file.setAttribute(l, "builds", std::int64_t(list_.builds()));
  file.write(group + "/wall_history_wall", widen(wall_history_.wall));
  file.write(group + "/wall_history_shear", flattenVec3(wall_history_.shear));
  file.setAttribute(group, "time", time_);
  file.setAttribute(group, "steps", std::int64_t(steps_));
  file.setAttribute(group, "builds_since_sort", std::int64_t(builds_since_sort_));
  file.setAttribute(group, "forces_valid", std::int64_t(forces_valid_ ? 1 : 0));
  file.setAttribute(group, "max_overlap_seen", max_overlap_seen_);
}

void DemSystem::loadState(const h5::File& file, const std::string& group) {
  DemParticles& p = particles_;
  p.x = unflattenVec3(file.readDoubles(group + "/x"));
  const std::size_t n = p.x.size();
  auto vec3 = [&](const std::string& name) {
    auto v = unflattenVec3(file.readDoubles(group + "/" + name));
    if (v.size() != n)
      throw RunError("DEM checkpoint " + file.path() + ":" + group + "/" + name + " has " +
                     std::to_string(v.size()) + " entries for " + std::to_string(n) + " particles");
    return v;
  };
  p.v = vec3("v");
  p.omega = vec3("omega");
  p.force = vec3("force");
  p.torque = vec3("torque");
  p.fluid_force = vec3("fluid_force");
  p.radius = file.readDoubles(group + "/radius");
  p.mass = file.readDoubles(group + "/mass");
  p.inv_mass = file.readDoubles(group + "/inv_mass");
  p.inv_inertia = file.readDoubles(group + "/inv_inertia");
  p.id = narrow<std::uint64_t>(file.readInt64s(group + "/id"));
  if (p.radius.size() != n || p.mass.size() != n || p.inv_mass.size() != n || p.inv_inertia.size() != n ||
      p.id.size() != n)
    throw RunError("DEM checkpoint " + file.path() + ":" + group + ": particle arrays of different lengths");
  const std::string l = group + "/list";
  list_.row_start = narrow<NeighbourList::Index>(file.readInt64s(l + "/row_start"));
  list_.j = narrow<NeighbourList::Index>(file.readInt64s(l + "/j"));
  list_.shear = unflattenVec3(file.readDoubles(l + "/shear"));
  list_.col_start = narrow<NeighbourList::Index>(file.readInt64s(l + "/col_start"));
  list_.col_pair = narrow<NeighbourList::Index>(file.readInt64s(l + "/col_pair"));
  list_.wall_start = narrow<NeighbourList::Index>(file.readInt64s(l + "/wall_start"));
  list_.wall_id = narrow<NeighbourList::Index>(file.readInt64s(l + "/wall_id"));
  list_.restore(unflattenVec3(file.readDoubles(l + "/x_at_build")), long(file.intAttribute(l, "builds")));
  pair_forces_.resize(list_.pairs());
  wall_history_.wall = narrow<int>(file.readInt64s(group + "/wall_history_wall"));
  wall_history_.shear = unflattenVec3(file.readDoubles(group + "/wall_history_shear"));
  if (wall_history_.wall.size() != n * WallHistory::slots || wall_history_.shear.size() != n * WallHistory::slots)
    throw RunError("DEM checkpoint " + file.path() + ":" + group + ": wall history does not match the particles");
  time_ = file.doubleAttribute(group, "time");
  steps_ = long(file.intAttribute(group, "steps"));
  builds_since_sort_ = long(file.intAttribute(group, "builds_since_sort"));
  forces_valid_ = file.intAttribute(group, "forces_valid") != 0;
  max_overlap_seen_ = file.doubleAttribute(group, "max_overlap_seen");
}

}  // namespace rcfd
