#include "scene/SceneChecks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>

#include "cfddem/DemFilling.hpp"
#include "cfddem/DemMaterial.hpp"
#include "scene/DatabaseSchedule.hpp"
#include "scene/SchemaExplainer.hpp"

namespace rcfd {
namespace {

using nlohmann::json;

std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

std::string point(const Vec3& p) { return "[" + num(p.x()) + ", " + num(p.y()) + ", " + num(p.z()) + "]"; }

double tanDeg(double deg) { return std::tan(deg * std::numbers::pi / 180.0); }

/// Iterative, so that a document nested thousands deep cannot exhaust the stack.
void findLimitViolations(const json& document, std::vector<Violation>& out) {
  struct Item {
    const json* value;
    std::string pointer;
    int depth;
  };
  std::vector<Item> pending{{&document, "", 0}};
  while (!pending.empty()) {
    Item item = std::move(pending.back());
    pending.pop_back();
    const json& value = *item.value;
    if (value.is_number_float() && !std::isfinite(value.get<double>())) {
      out.push_back({item.pointer, "number out of range (not a finite double)"});
    } else if (value.is_number_unsigned() &&
               value.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
      out.push_back({item.pointer, describeValue(value) + " is beyond the largest supported integer " +
                                       std::to_string(std::numeric_limits<std::int64_t>::max())});
    } else if (value.is_structured() && item.depth >= kMaxDocumentDepth) {
      out.push_back({item.pointer, "nested deeper than " + std::to_string(kMaxDocumentDepth) +
                                       " levels; no scene or job key is nested like this"});
    } else if (value.is_array() && value.size() > kMaxArrayItems) {
      out.push_back({item.pointer, "array of " + std::to_string(value.size()) + " items is longer than the " +
                                       std::to_string(kMaxArrayItems) + " allowed"});
    } else if (value.is_object()) {
      for (auto it = value.rbegin(); it != value.rend(); ++it) {
        pending.push_back({&*it, appendPointer(item.pointer, it.key()), item.depth + 1});
      }
    } else if (value.is_array()) {
      for (std::size_t i = value.size(); i-- > 0;) {
        pending.push_back({&value[i], appendPointer(item.pointer, std::to_string(i)), item.depth + 1});
      }
    }
    if (out.size() >= 20) return;  // enough to fix the document; do not flood
  }
}

bool inside(const Vec3& p, const Vec3& lower, const Vec3& upper) {
  return (p.array() >= lower.array()).all() && (p.array() <= upper.array()).all();
}

std::string boxText(const Vec3& lower, const Vec3& upper) {
  return "x in [" + num(lower.x()) + ", " + num(upper.x()) + "], y in [" + num(lower.y()) + ", " +
         num(upper.y()) + "], z in [" + num(lower.z()) + ", " + num(upper.z()) + "]";
}

void checkApparatus(const ApparatusSpec& a, std::vector<Violation>& out) {
  if (a.type != ApparatusSpec::Type::PrismaticSpoutedBed) return;
  if (a.inlet_width >= a.width) {
    out.push_back({"/apparatus/inlet_width", num(a.inlet_width) + " m is not < the width " + num(a.width) + " m"});
    return;
  }
  // The V-bottom rises from the slot edge x = inlet_width/2 to the side wall x = width/2.
  const double vTop = 0.5 * (a.width - a.inlet_width) * tanDeg(a.prism_angle_deg);
  if (vTop >= a.height) {
    out.push_back({"/apparatus/height", num(a.height) + " m does not clear the top of the V-bottom at y = " +
                                            num(vTop) + " m (width, inlet_width, prism_angle_deg)"});
  }
  if (!a.draft_plates) return;
  const auto& p = *a.draft_plates;
  const double outer = 0.5 * p.gap + p.thickness;
  if (outer >= 0.5 * a.width) {
    out.push_back({"/apparatus/draft_plates/gap", "plates' outer faces at x = +-" + num(outer) +
                                                      " m are not inside the side walls at +-" + num(0.5 * a.width) + " m"});
    return;
  }
  const double wallBelow = std::max(0.0, (outer - 0.5 * a.inlet_width) * tanDeg(a.prism_angle_deg));
  if (p.elevation <= wallBelow) {
    out.push_back({"/apparatus/draft_plates/elevation",
                   num(p.elevation) + " m is not above the V-bottom beneath the plates' outer faces (x = +-" +
                       num(outer) + " m, wall at y = " + num(wallBelow) + " m): the plates would cut into the wall"});
  }
  if (p.elevation + p.height > a.height) {
    out.push_back({"/apparatus/draft_plates/height", "plates reach y = " + num(p.elevation + p.height) +
                                                         " m, above the chamber height " + num(a.height) + " m"});
  }
}

/// Open volume of the chamber below the height y [m3]: the box's, or the prism's cross-section up to y
/// (the V-bottom's slot widening by 2 / tan(angle) per metre up to its top, the full width above, less
/// the draft plates) times its depth.
double openVolumeBelow(const ApparatusSpec& a, double y) {
  if (a.type == ApparatusSpec::Type::Box) return a.size.x() * a.size.z() * std::clamp(y, 0.0, a.size.y());
  y = std::clamp(y, 0.0, a.height);
  const double tanA = tanDeg(a.prism_angle_deg);
  const double vTop = 0.5 * (a.width - a.inlet_width) * tanA;
  const double inV = std::min(y, vTop);
  double area = a.inlet_width * inV + inV * inV / tanA + a.width * std::max(0.0, y - vTop);
  if (a.draft_plates) {
    const auto& p = *a.draft_plates;
    area -= 2.0 * p.thickness * std::max(0.0, std::min(y, p.elevation + p.height) - p.elevation);
  }
  return std::max(0.0, area) * a.depth;
}

}  // namespace

void apparatusBounds(const ApparatusSpec& a, Vec3& lower, Vec3& upper) {
  if (a.type == ApparatusSpec::Type::Box) {
    lower = Vec3(-0.5 * a.size.x(), 0.0, 0.0);
    upper = Vec3(0.5 * a.size.x(), a.size.y(), a.size.z());
  } else {
    lower = Vec3(-0.5 * a.width, 0.0, 0.0);
    upper = Vec3(0.5 * a.width, a.height, a.depth);
  }
}

std::vector<Violation> checkDatabaseScene(const Scene& s) {
  std::vector<Violation> out;
  // The filling pours the bed from its region (defaultFillRegion) into the chamber below it: a bed that
  // does not fit there, poured as loosely as a bed packs (alpha_P 0.5; a slice a few parcels deep packs
  // no denser), would bury the region and the filling would try for as long as it runs. Refused before
  // the job starts.
  constexpr double kPouredPacking = 0.5;
  const FillRegion region = defaultFillRegion(s.apparatus);
  const double regionBottom = region.lower.y();
  // Parcels are inserted whole, clear of the region's walls: it must be wider, higher and deeper than one.
  const double parcel = s.dem.coarse_graining * s.particles.diameter;
  const Vec3 regionSize = region.upper - region.lower;
  if (regionSize.minCoeff() <= 1.02 * parcel) {
    out.push_back({"/particles/diameter", "a parcel of coarse_graining x diameter = " + num(parcel) +
                                              " m does not fit the region the bed is poured from (" +
                                              num(regionSize.x()) + " x " + num(regionSize.y()) + " x " +
                                              num(regionSize.z()) + " m, y from " + num(region.lower.y()) +
                                              " m): at most " + num(regionSize.minCoeff() / 1.02) + " m"});
  }
  const double below = openVolumeBelow(s.apparatus, regionBottom);
  const double poured = s.process.bed_mass / (kPouredPacking * s.particles.density);
  if (poured > below) {
    out.push_back({"/process/bed_mass", num(s.process.bed_mass) + " kg poured (alpha_P " + num(kPouredPacking) +
                                            ") fills " + num(poured) + " m3, more than the chamber's open volume below " +
                                            "the filling region (y < " + num(regionBottom) + " m), " + num(below) +
                                            " m3: at most " + num(below * kPouredPacking * s.particles.density) +
                                            " kg fits"});
  }
  // The gas enters through the prism's inlet slot; a box has walls all round (GasSolver refuses it).
  if (s.apparatus.type == ApparatusSpec::Type::Box && s.hasEffect("gas")) {
    const auto at = std::find(s.effects.begin(), s.effects.end(), "gas") - s.effects.begin();
    out.push_back({"/effects/" + std::to_string(at), "the gas needs an inlet: a box's bottom is a wall, the effect gas "
                                                     "needs the inlet slot of a prismatic_spouted_bed"});
  }
  // The DEM time step against the Rayleigh time of the parcels (the job would refuse it at start).
  try {
    checkTimeStep(DemMaterial::fromScene(s), s.dem.time_step, s.dem.max_rayleigh_fraction);
  } catch (const InputError& e) {
    for (const auto& v : e.violations()) out.push_back(v);
  }
  for (auto& v : DatabaseSchedule::violations(s)) out.push_back(std::move(v));
  return out;
}

std::vector<Violation> documentLimitViolations(const json& document) {
  std::vector<Violation> out;
  findLimitViolations(document, out);
  return out;
}

std::vector<Violation> checkSceneSemantics(const Scene& s, const json& document) {
  std::vector<Violation> out;
  checkApparatus(s.apparatus, out);
  Vec3 lower, upper;
  apparatusBounds(s.apparatus, lower, upper);
  const Vec3 extent = upper - lower;

  static const char* axes[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    // One cell across an extent is a grid (the pseudo-2D cases other codes write); a cell larger than
    // the apparatus is not: the grid would silently shrink it to the extent.
    if (s.grid.cell_size[i] > extent[i] * (1.0 + 1e-9)) {
      out.push_back({"/grid/cell_size", "cell size " + num(s.grid.cell_size[i]) + " m along " + axes[i] +
                                            " is larger than the apparatus extent " + num(extent[i]) +
                                            " m (allowed: at most the extent, one cell across it)"});
    }
  }
  const double parcel = s.dem.coarse_graining * s.particles.diameter;
  if (parcel >= s.grid.cell_size.minCoeff()) {
    out.push_back({"/dem/coarse_graining", "parcel diameter coarse_graining * diameter = " + num(parcel) +
                                               " m is not smaller than the smallest cell edge " +
                                               num(s.grid.cell_size.minCoeff()) + " m"});
  }

  std::set<std::string> names;
  for (std::size_t i = 0; i < s.probes.size(); ++i) {
    const std::string base = "/probes/" + std::to_string(i);
    if (!names.insert(s.probes[i].name).second) {
      out.push_back({base + "/name", "duplicate probe name \"" + s.probes[i].name + "\""});
    }
    if (!inside(s.probes[i].position, lower, upper)) {
      out.push_back({base + "/position", point(s.probes[i].position) + " is outside the apparatus's bounding box " +
                                             boxText(lower, upper)});
    }
  }

  // Spray positions matter only where spraying or the spray zone is used; a box verification case
  // without them must not fail on the ProCell defaults.
  const bool sprayUsed = document.contains("spray") || s.hasEffect("spray") || s.hasEffect("residence_time");
  if (sprayUsed) {
    const auto& sp = s.spray;
    if (!inside(sp.nozzle_position, lower, upper)) {
      out.push_back({"/spray/nozzle_position", point(sp.nozzle_position) +
                                                   " is outside the apparatus's bounding box " + boxText(lower, upper)});
    }
    const auto& zone = sp.spray_zone;
    if (!inside(zone.apex, lower, upper)) {
      out.push_back({"/spray/spray_zone/apex", point(zone.apex) + " is outside the apparatus's bounding box " +
                                                   boxText(lower, upper)});
    }
    if (!(zone.y_min < zone.y_max)) {
      out.push_back({"/spray/spray_zone/y_min", num(zone.y_min) + " is not < y_max = " + num(zone.y_max)});
    }
    if (zone.y_min < zone.apex.y()) {
      out.push_back({"/spray/spray_zone/y_min", num(zone.y_min) + " is below the cone apex at y = " + num(zone.apex.y())});
    }
    if (zone.y_max > upper.y()) {
      out.push_back({"/spray/spray_zone/y_max", num(zone.y_max) + " is above the apparatus top y = " + num(upper.y())});
    }
  }
  if (s.hasEffect("spray")) {
    const auto& sp = s.spray;
    // Eq. (15): a droplet covers f = (d_D / 2 d_P)^2 of its particle; the deposition on particles as
    // spots needs droplets smaller than the particles (f < 1/4).
    if (!(sp.droplet_diameter < s.particles.diameter)) {
      out.push_back({"/spray/droplet_diameter", num(sp.droplet_diameter) +
                                                    " m is not smaller than the particle diameter /particles/diameter = " +
                                                    num(s.particles.diameter) + " m (Eq. 15 covers particles with droplet spots)"});
    }
    // A parcel carries at least one droplet (N_D,min = 1): with fewer, every parcel would be dropped
    // as residual at once and nothing deposit.
    const double dropletMass = sp.droplet_density * std::numbers::pi / 6.0 * std::pow(sp.droplet_diameter, 3);
    const double dropletRate = sp.mass_rate / dropletMass;
    if (sp.parcels_per_s > dropletRate) {
      out.push_back({"/spray/parcels_per_s", num(sp.parcels_per_s) + " parcels/s would carry " +
                                                 num(dropletRate / sp.parcels_per_s) +
                                                 " droplets each; every parcel needs at least one: at most " +
                                                 num(dropletRate) + " parcels/s (mass_rate / droplet mass)"});
    }
  }

  const auto& path = s.rcfd.path;
  if (path.min_sequence_fraction > path.max_sequence_fraction) {
    out.push_back({"/rcfd/path/min_sequence_fraction", num(path.min_sequence_fraction) +
                                                           " is not <= max_sequence_fraction = " +
                                                           num(path.max_sequence_fraction)});
  }
  if (path.type == "file" && path.file.empty()) {
    out.push_back({"/rcfd/path/file", "path type \"file\" needs a file name"});
  }
  if (!(s.rcfd.dt > 0.0)) out.push_back({"/rcfd/dt", num(s.rcfd.dt) + " is not > 0"});
  return out;
}

}  // namespace rcfd
