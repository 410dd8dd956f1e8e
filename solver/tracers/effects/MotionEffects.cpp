// The motion effects: they allocate nothing themselves and only switch parts of the MotionKernel on.
// transport (Eq. 9), fluctuation (Eq. 10), free_flight and walls.
#include <memory>

#include "tracers/FluctuationModel.hpp"
#include "tracers/TracerEffect.hpp"
#include "tracers/TracerIntegrator.hpp"

namespace rcfd {
namespace {

class TransportEffect final : public TracerEffect {
 public:
  explicit TransportEffect(const TracerContext& ctx)
      : maxCourant_(ctx.scene.rcfd.max_courant),
        midpoint_(tracerIntegrator(ctx.scene) == TracerIntegrator::Midpoint) {}
  void configureMotion(MotionSettings& m) override {
    m.transport = true;
    m.maxCourant = maxCourant_;
    m.midpoint = midpoint_;
  }

 private:
  double maxCourant_;
  bool midpoint_;
};

class FluctuationEffect final : public TracerEffect {
 public:
  explicit FluctuationEffect(const TracerContext& ctx)
      : model_(FluctuationModelRegistry::create(ctx.scene.rcfd.fluctuation_model)),
        d0_(ctx.scene.rcfd.d0),
        cap_(ctx.scene.rcfd.u_fluc_max) {}
  void configureMotion(MotionSettings& m) override {
    m.fluctuation = model_.get();
    m.d0 = d0_;
    m.uFlucMax = cap_;
  }

 private:
  std::unique_ptr<FluctuationModel> model_;
  double d0_, cap_;
};

class FreeFlightEffect final : public TracerEffect {
 public:
  explicit FreeFlightEffect(const TracerContext& ctx)
      : alpha_(ctx.scene.rcfd.free_flight_alpha), restitution_(ctx.scene.dem.restitution.particle_wall) {}
  void configureMotion(MotionSettings& m) override {
    m.freeFlight = true;
    m.freeFlightAlpha = alpha_;
    m.wallRestitution = restitution_;
  }

 private:
  double alpha_, restitution_;
};

class WallsEffect final : public TracerEffect {
 public:
  explicit WallsEffect(const TracerContext&) {}
  void configureMotion(MotionSettings& m) override { m.walls = true; }
};

const bool transportRegistered = TracerEffectRegistry::add(
    "transport", {"walls"}, 20, "Eq. (9): tracers move with u_P^rec (+ u_fluc)",
    [](TracerContext& c) { return std::make_unique<TransportEffect>(c); });
const bool fluctuationRegistered = TracerEffectRegistry::add(
    "fluctuation", {"transport", "tracer_volume_fraction"}, 21,
    "Eq. (10): random-walk velocity relaxing tracer over-packing (rcfd.fluctuation_model)",
    [](TracerContext& c) { return std::make_unique<FluctuationEffect>(c); });
const bool freeFlightRegistered = TracerEffectRegistry::add(
    "free_flight", {"transport"}, 22,
    "single-sphere drag and gravity where alpha_P^rec < rcfd.free_flight_alpha",
    [](TracerContext& c) { return std::make_unique<FreeFlightEffect>(c); });
const bool wallsRegistered = TracerEffectRegistry::add(
    "walls", {}, 23, "reflection at the exact walls, plates, inlet and outlet",
    [](TracerContext& c) { return std::make_unique<WallsEffect>(c); });

}  // namespace
}  // namespace rcfd
