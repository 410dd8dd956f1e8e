#include "import/OpenFoamImport.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>

#include "analysis/ReferenceStatistics.hpp"
#include "cfddem/ReferenceRecorder.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/FieldDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/SprayZone.hpp"
#include "geometry/XdmfGrid.hpp"
#include "import/CartesianMapping.hpp"
#include "import/FoamFile.hpp"
#include "import/OpenFoamFieldReader.hpp"
#include "import/OpenFoamMesh.hpp"

namespace rcfd::openfoam {
namespace fs = std::filesystem;

namespace {

/// Relative spread allowed between written times (their names are rounded to timePrecision digits).
constexpr double kTimeSpacingTolerance = 1e-3;
/// Share of the mesh volume that may lie outside the scene's grid before the case is refused as being
/// in other coordinates.
constexpr double kOutsideVolumeTolerance = 0.01;

/// Spray-zone stays of parcels known by (origProcId, origId), observed once per frame, with the rule of
/// analysis/ZoneStays.hpp: a parcel inside at frame e and first seen outside again at frame s stayed
/// s - e frames; stays open when first seen, when the parcel vanished (left the domain) or at the end
/// are not counted.
class IdentifiedStays {
 public:
  /// Observes one parcel at frame `frame`; false if the identity was already seen in this frame.
  bool observe(std::int64_t proc, std::int64_t id, bool inside, std::int64_t frame) {
    auto [it, isNew] = members_.try_emplace({proc, id}, Member{});
    Member& m = it->second;
    if (m.lastSeen == frame) return false;
    const bool continuous = !isNew && m.lastSeen == frame - 1;
    m.lastSeen = frame;
    if (!continuous) {  // first seen, or back after a gap: an entry we did not see is unknown
      m.entry = inside ? kUnknown : kOutside;
      return true;
    }
    if (inside) {
      if (m.entry == kOutside) m.entry = frame;
    } else {
      if (m.entry >= 0) durations_.push_back(frame - m.entry);
      m.entry = kOutside;
    }
    return true;
  }
  std::size_t members() const { return members_.size(); }
  std::int64_t openAtEnd(std::int64_t lastFrame) const {
    std::int64_t n = 0;
    for (const auto& [key, m] : members_) n += m.lastSeen == lastFrame && m.entry != kOutside;
    return n;
  }
  /// Completed stays [s], increasing.
  std::vector<double> durations(double dt) const {
    std::vector<std::int64_t> sorted = durations_;
    std::sort(sorted.begin(), sorted.end());
    std::vector<double> out;
    out.reserve(sorted.size());
    for (std::int64_t d : sorted) out.push_back(double(d) * dt);
    return out;
  }

 private:
  static constexpr std::int64_t kOutside = -1, kUnknown = -2;
  struct Member {
    std::int64_t entry = kOutside;
    std::int64_t lastSeen = -1;
  };
  std::map<std::pair<std::int64_t, std::int64_t>, Member> members_;
  std::vector<std::int64_t> durations_;
};

/// The bed pressure drop from the gas pressure `p`, as the database job reports it (the pressure where
/// the gas enters less where it leaves, without the gas's own hydrostatic head): the volume-weighted
/// mean pressure of the mesh cells in the grid's lowest row of cells less that of its highest row, less
/// rho_G g times the height between the two rows' mean centres. The rows rather than the inlet and
/// outlet patches: a zeroGradient patch writes no value, and the rows exist in every case that fits the
/// scene's grid. A kinematic p ([0 2 -2 0 0 0 0], what incompressible solvers such as MPPICFoam and
/// DPMFoam write) is multiplied by the scene's gas density; a p in Pa ([1 -1 -2 0 0 0 0]) is taken as
/// it is.
class RowPressureDrop {
 public:
  RowPressureDrop(const CartesianGrid& grid, const std::vector<CellGeometry>& meshes) : rows_(meshes.size()) {
    const double bottomTop = grid.origin.y() + grid.spacing.y();
    const double topBottom = grid.upperCorner().y() - grid.spacing.y();
    std::array<double, 2> heightSum{};
    for (std::size_t p = 0; p < meshes.size(); ++p)
      for (std::int64_t k = 0; k < meshes[p].cellCount(); ++k) {
        const double y = meshes[p].centres[std::size_t(k)].y(), v = meshes[p].volumes[std::size_t(k)];
        const int row = y < bottomTop ? 0 : y >= topBottom ? 1 : -1;
        if (row < 0) continue;
        rows_[p].push_back({k, row, v});
        volume_[std::size_t(row)] += v;
        heightSum[std::size_t(row)] += v * y;
      }
    if (usable()) rise_ = heightSum[1] / volume_[1] - heightSum[0] / volume_[0];
  }

  /// Both rows hold mesh cells (a grid one cell high has no second row).
  bool usable() const { return volume_[0] > 0.0 && volume_[1] > 0.0; }

  void beginFrame() { sum_ = {}; }
  /// The pressure of part p's cells (one value per cell).
  void add(std::size_t part, const std::vector<double>& pressure) {
    for (const RowCell& c : rows_[part]) sum_[std::size_t(c.row)] += c.volume * pressure[std::size_t(c.cell)];
  }
  /// [Pa]: `pressureScale` turns p into Pa; `gasWeight` is rho_G g [Pa/m].
  double finishFrame(double pressureScale, double gasWeight) const {
    return pressureScale * (sum_[0] / volume_[0] - sum_[1] / volume_[1]) - gasWeight * rise_;
  }

 private:
  struct RowCell {
    std::int64_t cell;
    int row;  ///< 0 lowest, 1 highest
    double volume;
  };
  std::vector<std::vector<RowCell>> rows_;  ///< per part
  std::array<double, 2> volume_{}, sum_{};
  double rise_ = 0.0;  ///< height of the top row's mean centre above the bottom row's [m]
};

/// Whether p is kinematic (true) or in Pa (false), from its dimensions; InputError naming the file
/// otherwise.
bool kinematicPressure(const Dimensions& d, const fs::path& file) {
  const Dimensions kinematic{0, 2, -2, 0, 0, 0, 0}, pascal{1, -1, -2, 0, 0, 0, 0};
  if (d == kinematic) return true;
  if (d == pascal) return false;
  std::string text;
  for (double e : d) text += (text.empty() ? "" : " ") + std::to_string(int(e));
  throw InputError(file.string(), "dimensions",
                   "[" + text + "]: a pressure is kinematic [0 2 -2 0 0 0 0] (m2/s2) or in Pa [1 -1 -2 0 0 0 0]");
}

/// The gravity of the case, constant/g's value (0, -9.81, 0 when the case has none) [m/s2].
Eigen::Vector3d caseGravity(const fs::path& root) {
  const auto file = FoamFile::locate(root / "constant/g");
  if (!file) return {0.0, -9.81, 0.0};
  FoamFile f = FoamFile::read(*file);
  if (!f.seekKeyword("value")) f.fail("value", "no value entry");
  f.expect('(', "value");
  Eigen::Vector3d g;
  for (int c = 0; c < 3; ++c) g[c] = f.scalar("value");
  f.expect(')', "value");
  return g;
}

double evenSpacing(const std::vector<WrittenTime>& times, const fs::path& where) {
  const std::size_t n = times.size();
  if (n < std::size_t(layout::minimumFrames))
    throw InputError(where.string(), "times",
                     std::to_string(n) + " written time(s) selected: a field database needs at least " +
                         std::to_string(layout::minimumFrames) + " frames");
  const double dt = (times.back().value - times.front().value) / double(n - 1);
  for (std::size_t i = 1; i < n; ++i) {
    const double step = times[i].value - times[i - 1].value;
    if (!(dt > 0.0) || std::abs(step - dt) > kTimeSpacingTolerance * dt)
      throw InputError(where.string(), "times",
                       "written times are not evenly spaced: " + times[i - 1].name + " to " + times[i].name +
                           " is " + std::to_string(step) + " s, the mean spacing " + std::to_string(dt) +
                           " s; select an evenly written range with --times A:B (job: \"times\")");
  }
  return dt;
}

Eigen::Vector3d at(const std::vector<double>& xyz, std::size_t i) {
  return Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
}

void removeQuietly(const fs::path& p) {
  std::error_code ec;
  fs::remove(p, ec);
}

}  // namespace

ImportResult importOpenFoam(const Scene& scene, const ImportOptions& options) {
  const OpenFoamCase c = OpenFoamCase::open(options.caseDir, options.times, options.cloud);
  const double dtRec = evenSpacing(c.times, c.parts.front());
  const std::size_t frames = c.times.size();

  const Apparatus apparatus(scene.apparatus);
  const CartesianGrid grid = makeGrid(apparatus, scene.grid);
  const std::vector<double> open = openFractions(apparatus, grid);
  CartesianMapping mapping(grid, std::vector<float>(open.begin(), open.end()));
  const SprayZone zone(scene.spray.spray_zone, apparatus);

  std::vector<CellGeometry> meshes;
  double meshVolume = 0.0, outsideVolume = 0.0;
  std::int64_t meshCells = 0;
  for (const auto& part : c.parts) {
    meshes.push_back(readCellGeometry(part / "constant/polyMesh"));
    for (std::int64_t k = 0; k < meshes.back().cellCount(); ++k) {
      bool outside = false;
      mapping.receivingCell(meshes.back().centres[std::size_t(k)], nullptr, &outside);
      if (outside) outsideVolume += meshes.back().volumes[std::size_t(k)];
    }
    meshVolume += meshes.back().totalVolume();
    meshCells += meshes.back().cellCount();
  }
  if (outsideVolume > kOutsideVolumeTolerance * meshVolume) {
    const Eigen::Vector3d hi = grid.upperCorner();
    throw InputError(c.root.string(), "mesh",
                     std::to_string(100.0 * outsideVolume / meshVolume) +
                         " % of the mesh volume lies outside the scene's grid (x " + std::to_string(grid.origin.x()) +
                         " .. " + std::to_string(hi.x()) + ", y " + std::to_string(grid.origin.y()) + " .. " +
                         std::to_string(hi.y()) + ", z " + std::to_string(grid.origin.z()) + " .. " +
                         std::to_string(hi.z()) +
                         " m): the case must use the scene's coordinates (x lateral, y up, z depth; "
                         "OpenFOAM's transformPoints moves a mesh)");
  }

  RowPressureDrop pressureDrop(grid, meshes);
  const bool withPressure = !c.pressureField.empty() && pressureDrop.usable();
  const Eigen::Vector3d gravity = caseGravity(c.root);
  const double gasWeight = scene.gas.density * std::max(0.0, -gravity.y());

  const fs::path finalPath = options.databasePath;
  const fs::path partial = finalPath.string() + ".partial";
  removeQuietly(partial);
  ImportResult result;
  result.grid = grid;
  result.alphaPMean.assign(std::size_t(grid.cellCount()), 0.0);
  nlohmann::json summary;
  try {
    const bool lagrangian = c.particleSource == ParticleSource::Lagrangian;
    // An Eulerian particle phase has only its mean velocity per cell: no spread to write.
    const bool spread = options.velocitySpread && lagrangian;
    mapping.recordVelocitySpread(spread);
    FieldDatabaseWriterOptions writeOptions;
    writeOptions.velocitySpread = spread;
    FieldDatabaseWriter writer(partial.string(), grid, mapping.fluidFraction(), dtRec, scene.source_json,
                               writeOptions);
    std::vector<double> pressureDropPa;
    std::optional<bool> kinematic;  // p's units, from the first time read
    IdentifiedStays stays;
    bool identities = lagrangian, identitiesSeen = false;
    std::string identitiesMissingAt;
    std::vector<double> holdupParcels, holdupParticles;
    std::int64_t parcelsMin = -1, parcelsMax = 0;
    double worstRelativeError = 0.0, firstParticleVolume = 0.0;
    MappingCounts worst;
    for (std::size_t n = 0; n < frames; ++n) {
      if (options.stopRequested && options.stopRequested())
        throw Cancelled("stopped after " + std::to_string(n) + " of " + std::to_string(frames) +
                        " frames; the partial database was removed");
      const WrittenTime& t = c.times[n];
      mapping.beginFrame();
      pressureDrop.beginFrame();
      std::int64_t parcels = 0;
      double inParcels = 0.0, inParticles = 0.0;
      for (std::size_t p = 0; p < c.parts.size(); ++p) {
        const CellGeometry& mesh = meshes[p];
        const fs::path dir = c.timeDir(p, t);
        const std::vector<double> ug = readInternalField(dir / c.gasVelocityField, 3, mesh.cellCount());
        for (std::int64_t k = 0; k < mesh.cellCount(); ++k)
          mapping.addGas(mesh.centres[std::size_t(k)], mesh.volumes[std::size_t(k)], at(ug, std::size_t(k)));
        if (withPressure) {
          Dimensions dims;
          const fs::path file = dir / c.pressureField;
          pressureDrop.add(p, readInternalField(file, 1, mesh.cellCount(), dims));
          if (kinematic && *kinematic != kinematicPressure(dims, file))
            throw InputError(file.string(), "dimensions", "differ from those of the first time's " + c.pressureField);
          kinematic = kinematicPressure(dims, file);
        }
        if (!lagrangian) {
          const std::vector<double> alpha = readInternalField(dir / c.particleFractionField, 1, mesh.cellCount());
          const std::vector<double> up = readInternalField(dir / c.particleVelocityField, 3, mesh.cellCount());
          const bool voidFraction = c.particleSource == ParticleSource::EulerianVoidFraction;
          for (std::int64_t k = 0; k < mesh.cellCount(); ++k) {
            const double a = voidFraction ? 1.0 - alpha[std::size_t(k)] : alpha[std::size_t(k)];
            if (a < -1e-9 || a > 1.0 + 1e-9)
              throw InputError((dir / c.particleFractionField).string(), "internalField",
                               "cell " + std::to_string(k) + ": particle volume fraction " + std::to_string(a) +
                                   " outside [0, 1]");
            const double v = std::clamp(a, 0.0, 1.0) * mesh.volumes[std::size_t(k)];
            if (v > 0.0) mapping.addParticles(mesh.centres[std::size_t(k)], v, at(up, std::size_t(k)));
          }
          continue;
        }
        const fs::path cloudDir = dir / "lagrangian" / c.cloud;
        std::error_code ec;
        if (!fs::is_directory(cloudDir, ec)) continue;  // OpenFOAM writes no directory for an empty cloud
        const CloudParcels cloud = readCloud(cloudDir);
        if (cloud.size() > 0 && !cloud.hasIdentities()) {
          identities = false;
          if (identitiesMissingAt.empty()) identitiesMissingAt = (cloudDir / "origId").string();
        }
        parcels += std::int64_t(cloud.size());
        for (std::size_t i = 0; i < cloud.size(); ++i) {
          const double d = cloud.diameter[i];
          const double volume = cloud.nParticle[i] * std::numbers::pi * d * d * d / 6.0;
          const Eigen::Vector3d x = at(cloud.position, i);
          mapping.addParticles(x, volume, at(cloud.velocity, i));
          const bool inside = zone.contains(x);
          inParcels += inside;
          inParticles += inside ? cloud.nParticle[i] : 0.0;
          if (identities && cloud.hasIdentities()) {
            identitiesSeen = true;
            // A reconstructed case without origProcId: one processor made every parcel.
            const std::int64_t proc = cloud.origProcId.empty() ? 0 : cloud.origProcId[i];
            if (!stays.observe(proc, cloud.origId[i], inside, std::int64_t(n)))
              throw InputError(cloudDir.string(), "origId",
                               "parcel (origProcId " + std::to_string(proc) + ", origId " +
                                   std::to_string(cloud.origId[i]) + ") appears twice at time " + t.name +
                                   ": identities must be unique");
          }
        }
      }
      MappingCounts counts;
      const FieldFrame frame = mapping.finishFrame(counts);
      writer.append(frame);
      for (std::size_t k = 0; k < frame.alpha_p.size(); ++k) result.alphaPMean[k] += frame.alpha_p[k] / double(frames);
      if (counts.particleVolume > 0.0)
        worstRelativeError = std::max(worstRelativeError, std::abs(counts.mappedParticleVolume - counts.particleVolume) /
                                                              counts.particleVolume);
      if (n == 0) firstParticleVolume = counts.particleVolume;
      worst.redirected = std::max(worst.redirected, counts.redirected);
      worst.outsideGrid = std::max(worst.outsideGrid, counts.outsideGrid);
      worst.overfullCells = std::max(worst.overfullCells, counts.overfullCells);
      worst.gasFilledCells = std::max(worst.gasFilledCells, counts.gasFilledCells);
      parcelsMin = parcelsMin < 0 ? parcels : std::min(parcelsMin, parcels);
      parcelsMax = std::max(parcelsMax, parcels);
      if (withPressure) pressureDropPa.push_back(pressureDrop.finishFrame(*kinematic ? scene.gas.density : 1.0, gasWeight));
      holdupParcels.push_back(inParcels);
      holdupParticles.push_back(inParticles);
      if (options.progress) options.progress(double(n + 1) / double(frames));
    }
    writer.close();

    summary = {{"case", c.root.string()},
               {"decomposed", c.decomposed},
               {"parts", c.parts.size()},
               {"mesh_cells", meshCells},
               {"mesh_volume_m3", meshVolume},
               {"frames", frames},
               {"first_time_s", c.times.front().value},
               {"last_time_s", c.times.back().value},
               {"dt_rec", dtRec},
               {"fields", {{"gas_velocity", c.gasVelocityField}}},
               {"particle_source", lagrangian ? "lagrangian" : "eulerian"},
               {"velocity_spread", spread},
               {"particle_volume", {{"first_frame_m3", firstParticleVolume},
                                    {"max_relative_error", worstRelativeError}}},
               {"mapping", {{"max_redirected", worst.redirected},
                            {"max_outside_grid", worst.outsideGrid},
                            {"max_overfull_cells", worst.overfullCells},
                            {"max_gas_filled_cells", worst.gasFilledCells}}},
               {"grid", {{"shape", grid.shape}, {"spacing", {grid.spacing.x(), grid.spacing.y(), grid.spacing.z()}}}}};
    if (lagrangian) {
      summary["cloud"] = c.cloud;
      summary["parcels"] = {{"min", parcelsMin}, {"max", parcelsMax}};
    } else {
      summary["fields"]["particle_fraction"] = c.particleFractionField;
      summary["fields"]["particle_velocity"] = c.particleVelocityField;
    }

    // The reference series: sampled at the written times, the whole import is the reference period.
    nlohmann::json reference = {{"holdup", nullptr}, {"residence_time", nullptr}};
    if (lagrangian) {
      namespace L = analysis::reference_layout;
      h5::File db(partial.string(), h5::File::Mode::ReadWrite);
      double parcelsInside = 0.0, particlesInside = 0.0;
      for (std::size_t n = 0; n < frames; ++n) {
        parcelsInside += holdupParcels[n];
        particlesInside += holdupParticles[n];
      }
      const double particlesPerParcel = parcelsInside > 0.0 ? particlesInside / parcelsInside : 1.0;
      db.write(L::holdup, holdupParticles);
      db.setAttribute(L::holdup, L::holdupDt, dtRec);
      db.setAttribute(L::holdup, "t0", 0.0);
      db.setAttribute(L::holdup, "particles_per_parcel", particlesPerParcel);
      db.write(reference_series::holdupParcels, holdupParcels);
      db.setAttribute(reference_series::holdupParcels, "dt", dtRec);
      db.setAttribute(reference_series::holdupParcels, "t0", 0.0);
      reference["holdup"] = {{"mean", particlesInside / double(frames)},
                             {"mean_parcels", parcelsInside / double(frames)},
                             {"particles_per_parcel", particlesPerParcel}};
      if (identities && identitiesSeen) {
        const std::vector<double> durations = stays.durations(dtRec);
        double sum = 0.0;
        for (double d : durations) sum += d;
        if (!durations.empty()) {  // the calibration refuses an empty dataset
          db.write(L::durations, durations);
          db.setAttribute(L::durations, "dt", dtRec);
          db.setAttribute(L::durations, L::members, double(stays.members()));
          db.setAttribute(L::durations, L::period, double(frames) * dtRec);
        }
        reference["residence_time"] = {{"stays", durations.size()},
                                       {"censored", stays.openAtEnd(std::int64_t(frames) - 1)},
                                       {"mean_s", durations.empty() ? 0.0 : sum / double(durations.size())},
                                       {"members", stays.members()},
                                       {"sample_dt_s", dtRec}};
      } else {
        reference["residence_time_missing"] =
            "parcels carry no identities (" + (identitiesMissingAt.empty() ? std::string("no parcels") : identitiesMissingAt) +
            " absent): no spray-zone stays";
      }
      db.createGroup("/reference");
      db.setAttribute("/reference", "dt", dtRec);
      db.setAttribute("/reference", "reference_t0", 0.0);
      db.flush();
    } else {
      reference["missing"] = "an Eulerian particle phase has no parcels to follow: no holdup and no stays";
    }
    if (withPressure) {
      h5::File db(partial.string(), h5::File::Mode::ReadWrite);
      db.write(reference_series::pressureDrop, pressureDropPa);
      db.setAttribute(reference_series::pressureDrop, "dt", dtRec);
      db.setAttribute(reference_series::pressureDrop, "t0", 0.0);
      db.flush();
      reference["pressure_drop"] = pressureDropSummary(pressureDropPa, dtRec);
      reference["pressure_drop"]["field"] = c.pressureField;
      reference["pressure_drop"]["kinematic"] = *kinematic;
    } else {
      reference["pressure_drop"] = nullptr;
      reference["pressure_drop_missing"] =
          c.pressureField.empty() ? "the case writes no " + kPressureNames.front() + ": no pressure drop"
                                  : std::string("no mesh cell lies in the grid's lowest or highest row (or the grid is one cell high): no pressure drop between them");
    }
    summary["reference"] = reference;
  } catch (...) {
    removeQuietly(partial);
    throw;
  }
  std::error_code ec;
  fs::rename(partial, finalPath, ec);
  if (ec) throw RunError("cannot rename " + partial.string() + " to " + finalPath.string() + ": " + ec.message());
  xdmf::writeSidecar(finalPath.string(), xdmfGrid(grid), {}, xdmf::FrameSeries{"/frames", std::int64_t(frames), dtRec});
  summary["database"] = finalPath.string();
  result.summary = std::move(summary);
  return result;
}

}  // namespace rcfd::openfoam
