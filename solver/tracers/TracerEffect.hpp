#pragma once
/// \file TracerEffect.hpp
/// A tracer effect is one stage of the rCFD step, registered by name (LAMMPS styles, OpenFOAM run-time
/// selection) together with the effects it needs. A scene's `effects` list selects them; the
/// simulation constructs only those (so an effect not asked for allocates nothing and costs nothing).
///
/// Per step the simulation calls, for every effect in dependency order: beforeMove(), then the motion
/// kernel moves the tracers (configured by the motion effects through configureMotion()), then
/// afterMove() (beside the move for the effects that say afterMoveBesideMotion()).

#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/Hdf5.hpp"
#include "tracers/TracerContext.hpp"

namespace rcfd {

class FluctuationModel;

/// What the motion kernel does, assembled from the motion effects.
struct MotionSettings {
  bool transport = false;   ///< Eq. (9): dx/dt = u_P^rec + u_fluc
  bool walls = false;       ///< reflect at the exact walls
  bool freeFlight = false;  ///< single-sphere drag and gravity where alpha_P^rec < freeFlightAlpha
  const FluctuationModel* fluctuation = nullptr;  ///< Eq. (10) or the CFDEM form; null: none
  double d0 = 0.0;               ///< [m2/s]
  double uFlucMax = 1.0;         ///< [m/s]
  double freeFlightAlpha = 0.02; ///< [-]
  double maxCourant = 1.0;       ///< particle Courant bound for sub-steps [-]
  bool midpoint = true;          ///< Eq. (9) by the midpoint rule (2nd order) instead of Euler
  double wallRestitution = 0.75; ///< normal restitution of free-flying tracers at walls [-]
  bool vectorised = true;        ///< false: every tracer through the scalar path (tests compare both)
};

class TracerEffect {
 public:
  virtual ~TracerEffect() = default;
  virtual void configureMotion(MotionSettings&) {}
  virtual void beforeMove(TracerContext&) {}
  virtual void afterMove(TracerContext&) {}
  /// True when afterMove() reads nothing the motion kernel writes in the step (positions, velocities,
  /// TracerContext::nextTracerCell) and nothing that an effect whose afterMove() is not beside the
  /// motion writes there: then it runs on one thread of the kernel's team while the others move tracers
  /// (in effect order among such effects), with the same results as after the move. The spray effects
  /// are such: parcels, droplets and deposits depend on the step's frames and the tracers' cells and
  /// alpha_P at its start, not on where the tracers go.
  virtual bool afterMoveBesideMotion() const { return false; }
  /// Bytes this effect allocated (fields, series, per-tracer arrays).
  virtual std::size_t allocatedBytes() const { return 0; }
  /// Adds the effect's results to result.h5 and summary.json.
  virtual void writeResults(const TracerContext&, h5::File&, nlohmann::json&) const {}
  /// Writes the effect's figures (SVG) into `outDir`; returns the file names written.
  virtual std::vector<std::string> writeFigures(const TracerContext&, const std::string& outDir) const {
    return {};
  }
  /// The tracers were reordered: index j now holds the tracer that was at index from[j]. An effect with
  /// per-tracer state reorders it the same way.
  virtual void permuteTracers(TracerContext&, const std::vector<std::int32_t>& from) {}
  /// Checkpoint state under `group` (bit-exact restore).
  virtual void saveState(h5::File&, const std::string& group) const {}
  virtual void loadState(const h5::File&, const std::string& group) {}
};

/// Registration of tracer effects with their dependencies.
class TracerEffectRegistry {
 public:
  using Factory = std::function<std::unique_ptr<TracerEffect>(TracerContext&)>;
  struct Entry {
    std::string doc;
    std::vector<std::string> needs;
    int order = 0;  ///< position in the step among independent effects (lower first)
    Factory factory;
    bool readsVelocitySpread = false;  ///< reads the frames' velocity spread (FrameStorage::velocitySpread)
    bool velocitySpreadOptional = false;  ///< does without it (and says so) when the database has none
  };

  static bool add(const std::string& name, std::vector<std::string> needs, int order, std::string doc,
                  Factory factory, bool readsVelocitySpread = false, bool velocitySpreadOptional = false);
  static const std::map<std::string, Entry>& entries();
  static bool contains(const std::string& name);

  /// Checks a scene's tracer-stage effect list: every name known, every dependency present. Returns the
  /// names in execution order. Throws InputError naming /effects and listing the valid names.
  static std::vector<std::string> resolve(const std::vector<std::string>& requested);
  /// Whether any of the listed effects reads the frames' velocity spread: the database is then opened
  /// with it (and without it otherwise, so that it costs no memory).
  static bool needsVelocitySpread(const std::vector<std::string>& effects);
  /// Whether one of them cannot do without it (the database is then refused when it has none).
  static bool requiresVelocitySpread(const std::vector<std::string>& effects);
};

/// Effect names of the other stages (CFD-DEM, spray) that a tracer run ignores.
bool isTracerStageEffect(const std::string& name);

}  // namespace rcfd
