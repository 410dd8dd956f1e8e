#include "tracers/TracerSimulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>

#include "core/Errors.hpp"
#include "core/Permutation.hpp"
#include "geometry/ThinWalls.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/FrameInterpolation.hpp"

namespace rcfd {

TracerSimulation::TracerSimulation(const Scene& scene, std::shared_ptr<const FieldDatabase> database,
                                   RecurrencePath path, const TracerRunSettings& settings)
    : scene_(scene), database_(std::move(database)), path_(std::move(path)), settings_(settings) {
  const double dtRec = database_->dtRec();
  const double ratio = dtRec / scene_.rcfd.dt;
  stepsPerFrame_ = int(std::lround(ratio));
  linearBetweenFrames_ = frameInterpolation(scene_) == FrameInterpolation::Linear;
  if (!(scene_.rcfd.dt > 0.0) || stepsPerFrame_ < 1 || std::abs(ratio - stepsPerFrame_) > 1e-6 * ratio) {
    throw InputError("scene", "/rcfd/dt",
                     std::to_string(scene_.rcfd.dt) + " s must be dt_rec / k for a whole number k >= 1 (dt_rec = " +
                         std::to_string(dtRec) + " s of the database)");
  }
  if (scene_.rcfd.tracers < 1) throw InputError("scene", "/rcfd/tracers", "must be at least 1");
  if (scene_.rcfd.tracers > std::numeric_limits<std::int32_t>::max()) {  // TracerCloud::id, tracer cells
    throw InputError("scene", "/rcfd/tracers", "must be at most 2147483647");
  }
  const std::int64_t framesNeeded = settings_.steps / stepsPerFrame_ + 2;
  if (std::int64_t(path_.frames.size()) < framesNeeded) {
    throw RunError("recurrence path has " + std::to_string(path_.frames.size()) + " frames; the run needs " +
                   std::to_string(framesNeeded));
  }
  for (const int f : path_.frames) {
    if (f < 0 || f >= database_->frameCount()) {
      throw InputError("path", "/frames", "frame index " + std::to_string(f) + " outside [0, " +
                                              std::to_string(database_->frameCount() - 1) + "]");
    }
  }
  const auto effects = TracerEffectRegistry::resolve(scene_.effects);

  apparatus_ = std::make_unique<Apparatus>(scene_.apparatus);
  cloud_.resize(std::size_t(scene_.rcfd.tracers));
  const auto& p = scene_.particles;
  cloud_.particleVolume = std::numbers::pi / 6.0 * p.diameter * p.diameter * p.diameter;
  const double realParticles = scene_.process.bed_mass / (p.density * cloud_.particleVolume);
  cloud_.particlesPerTracer = realParticles / double(scene_.rcfd.tracers);

  context_ = std::make_unique<TracerContext>(scene_, *apparatus_, database_.get(), database_->grid(), cloud_,
                                             settings_.seed);
  auto& ctx = *context_;
  ctx.dt = scene_.rcfd.dt;
  ctx.totalSteps = settings_.steps;
  ctx.discardSteps = settings_.discardSteps;
  const auto& fluid = database_->fluidFraction();
  ctx.openVolume.resize(fluid.size());
  for (std::size_t c = 0; c < fluid.size(); ++c) ctx.openVolume[c] = fluid[c] * ctx.grid.cellVolume();
  ctx.plateFaces = plateFacesAbove(*apparatus_, ctx.grid);
  if (velocityInterpolation(scene_) == VelocityInterpolation::MassWeighted) ctx.stepFields.setMassWeight(kMassWeightFloor);

  loadFrames();
  placeTracers();

  MotionSettings motion;
  motion.vectorised = settings_.vectorisedKernel;
  for (const auto& name : effects) {
    effects_.push_back(TracerEffectRegistry::entries().at(name).factory(ctx));
    effects_.back()->configureMotion(motion);
    effectNames_.push_back(name);
  }
  kernel_ = std::make_unique<MotionKernel>(ctx, motion);
  keepsVelocities_ = motion.freeFlight;  // otherwise the velocities stay 0 and need no reordering
}

TracerSimulation::~TracerSimulation() = default;

void TracerSimulation::frameAt(std::int64_t step, int& frame, int& next, double& blend) const {
  const std::int64_t index = step / stepsPerFrame_;
  const int sub = int(step % stepsPerFrame_);
  frame = path_.frames[std::size_t(index)];
  next = frame;
  blend = 0.0;
  // Blend only inside a sequence: never across a jump of the path. Holding a frame is the default:
  // a structure that moves between two frames blends into two weaker ones, and tracers in either
  // move slower than the particles did (docs/accuracy.md, "Between frames").
  if (linearBetweenFrames_ && sub > 0 && !path_.isJump(index + 1)) {
    next = path_.frames[std::size_t(index + 1)];
    blend = double(sub) / stepsPerFrame_;
  }
}

void TracerSimulation::loadFrames() {
  int frame = 0, next = 0;
  double blend = 0.0;
  frameAt(context_->step, frame, next, blend);
  context_->frame = database_->frame(frame);
  context_->nextFrame = blend > 0.0 ? database_->frame(next) : nullptr;
  context_->blend = blend;
  context_->stepFields.invalidate();
}

void TracerSimulation::placeTracers() {
  // Cells are drawn with probability alpha_P^rec x open volume (Eq.-free initial condition of the
  // paper: the bed as the first frame has it); an empty first frame falls back to the open volume.
  const auto& ctx = *context_;
  const std::size_t cells = ctx.openVolume.size();
  std::vector<double> cdf(cells);
  double total = 0.0;
  for (std::size_t c = 0; c < cells; ++c) {
    total += std::max(0.0, double(ctx.frame->alpha_p[c])) * ctx.openVolume[c];
    cdf[c] = total;
  }
  if (!(total > 0.0)) {
    total = 0.0;
    for (std::size_t c = 0; c < cells; ++c) cdf[c] = (total += ctx.openVolume[c]);
  }
  if (!(total > 0.0)) throw InputError("database", "/grid/fluid_fraction", "no open cell to place tracers in");
  const std::int64_t n = std::int64_t(cloud_.size());
  const auto& grid = ctx.grid;
  std::int64_t failures = 0;
#pragma omp parallel for schedule(static) reduction(+ : failures) if (n > kParallelThreshold)
  for (std::int64_t i = 0; i < n; ++i) {
    CounterRng rng(settings_.seed, RngPurpose::Initialisation, std::uint64_t(i), 0);
    bool placed = false;
    for (int attempt = 0; attempt < 1000 && !placed; ++attempt) {
      const double u = rng.uniform() * total;
      const std::size_t c = std::min<std::size_t>(
          std::size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()), cells - 1);
      const auto ijk = grid.cellIjk(std::int64_t(c));
      const Eigen::Vector3d corner =
          grid.origin + grid.spacing.cwiseProduct(Eigen::Vector3d(ijk[0], ijk[1], ijk[2]));
      const Eigen::Vector3d p =
          corner + grid.spacing.cwiseProduct(Eigen::Vector3d(rng.uniform(), rng.uniform(), rng.uniform()));
      if (apparatus_->signedDistance(p) > 0.0) {
        cloud_.setPosition(std::size_t(i), p);
        placed = true;
      }
    }
    if (!placed) ++failures;
  }
  if (failures > 0) throw RunError(std::to_string(failures) + " tracers could not be placed inside the apparatus");
}

void TracerSimulation::step() {
  // A clock read per stage (tens of ns against milliseconds per step): the stage costs in one run.
  using Clock = std::chrono::steady_clock;
  auto& ctx = *context_;
  effectSeconds_.resize(effects_.size(), 0.0);
  auto since = [](Clock::time_point& t) {
    const Clock::time_point now = Clock::now();
    const double s = std::chrono::duration<double>(now - t).count();
    t = now;
    return s;
  };
  Clock::time_point t = Clock::now();
  if (settings_.sortInterval > 0 && ctx.step % settings_.sortInterval == 0) {
    sortTracers();
    sortSeconds_ += since(t);
  }
  for (std::size_t i = 0; i < effects_.size(); ++i) {
    effects_[i]->beforeMove(ctx);
    effectSeconds_[i] += since(t);
  }
  // Beside the move, on one thread: the effects whose afterMove() does not depend on it (timed on that
  // thread), and the next step's u_P^rec step field, which the move would otherwise wait for.
  std::function<void()> beside;
  const bool buildAhead = kernel_->settings().transport && ctx.step + 1 < settings_.steps;
  if (buildAhead ||
      std::any_of(effects_.begin(), effects_.end(), [](const auto& e) { return e->afterMoveBesideMotion(); })) {
    beside = [&] {
      Clock::time_point mine = Clock::now();
      for (std::size_t i = 0; i < effects_.size(); ++i) {
        if (!effects_[i]->afterMoveBesideMotion()) continue;
        effects_[i]->afterMove(ctx);
        effectSeconds_[i] += since(mine);
      }
      if (buildAhead) {
        int frame = 0, next = 0;
        double blend = 0.0;
        frameAt(ctx.step + 1, frame, next, blend);
        ctx.stepFields.buildAhead(ctx.grid, database_->frame(frame), blend > 0.0 ? database_->frame(next) : nullptr,
                                  blend, false);
      }
    };
  }
  kernel_->move(ctx, beside);
  motionSeconds_ += since(t);
  for (std::size_t i = 0; i < effects_.size(); ++i) {
    if (effects_[i]->afterMoveBesideMotion()) continue;
    effects_[i]->afterMove(ctx);
    effectSeconds_[i] += since(t);
  }
  ++ctx.step;
  loadFrames();
  frameSeconds_ += since(t);
}

std::vector<std::pair<std::string, double>> TracerSimulation::stageSeconds() const {
  std::vector<std::pair<std::string, double>> stages;
  for (std::size_t i = 0; i < effectNames_.size(); ++i) {
    stages.emplace_back(effectNames_[i], i < effectSeconds_.size() ? effectSeconds_[i] : 0.0);
  }
  stages.emplace_back("motion", motionSeconds_);
  stages.emplace_back("frames", frameSeconds_);
  stages.emplace_back("sort", sortSeconds_);
  return stages;
}

void TracerSimulation::resetStageSeconds() {
  effectSeconds_.assign(effects_.size(), 0.0);
  motionSeconds_ = frameSeconds_ = sortSeconds_ = 0.0;
}

void TracerSimulation::sortTracers() {
  auto& ctx = *context_;
  const std::size_t n = cloud_.size();
  const std::size_t cells = std::size_t(ctx.grid.cellCount());
  // Scratch kept between sorts (fresh arrays would cost their page faults every time) and swapped
  // with the arrays they replace.
  auto& s = sortScratch_;
  s.cell.resize(n), s.from.resize(n);
  s.start.assign(cells + 1, 0);
  const bool takesCells = ctx.nextTracerCell.size() == n;  // tracer_volume_fraction takes them back below
  if (takesCells && ctx.nextTracerCellStep == ctx.step) {
    s.cell.swap(ctx.nextTracerCell);  // the motion kernel found them for these positions
  } else {
    CellIndexer(ctx.grid).cellsOf(int(n), cloud_.x.data(), cloud_.y.data(), cloud_.z.data(), s.cell.data());
  }
  // Counting sort by cell, stable: the same order for any thread count and on resume.
  for (const std::int32_t c : s.cell) ++s.start[std::size_t(c) + 1];
  for (std::size_t c = 0; c < cells; ++c) s.start[c + 1] += s.start[c];
  for (std::size_t i = 0; i < n; ++i) s.from[std::size_t(s.start[std::size_t(s.cell[i])]++)] = std::int32_t(i);
  for (auto* values : {&cloud_.x, &cloud_.y, &cloud_.z}) applyPermutation(*values, s.from, s.doubles);
  if (keepsVelocities_) {
    for (auto* values : {&cloud_.vx, &cloud_.vy, &cloud_.vz}) applyPermutation(*values, s.from, s.doubles);
  }
  applyPermutation(cloud_.id, s.from, s.ints);
  for (auto& e : effects_) e->permuteTracers(ctx, s.from);
  if (takesCells) {  // the cells are known: tracer_volume_fraction takes them
    applyPermutation(s.cell, s.from, s.ints);
    ctx.nextTracerCell.swap(s.cell);
    ctx.nextTracerCellStep = ctx.step;
  } else {
    ctx.nextTracerCellStep = -1;
  }
}

const TracerEffect* TracerSimulation::effect(const std::string& name) const {
  for (std::size_t i = 0; i < effectNames_.size(); ++i) {
    if (effectNames_[i] == name) return effects_[i].get();
  }
  return nullptr;
}

std::size_t TracerSimulation::allocatedBytes(const std::string& name) const {
  const TracerEffect* e = effect(name);
  return e ? e->allocatedBytes() : 0;
}

void TracerSimulation::saveCheckpoint(const std::string& path) const {
  // Written beside the target and renamed over it, so a crash mid-write keeps the previous checkpoint.
  const std::string tmp = path + ".tmp";
  {
    h5::File f(tmp, h5::File::Mode::Create);
    f.write("/cloud/x", cloud_.x);
    f.write("/cloud/y", cloud_.y);
    f.write("/cloud/z", cloud_.z);
    f.write("/cloud/vx", cloud_.vx);
    f.write("/cloud/vy", cloud_.vy);
    f.write("/cloud/vz", cloud_.vz);
    f.write("/cloud/id", std::vector<std::int64_t>(cloud_.id.begin(), cloud_.id.end()));
    f.write("/state/step", std::vector<std::int64_t>{context_->step});
    f.write("/state/seed", std::vector<std::int64_t>{std::int64_t(settings_.seed)});
    for (std::size_t i = 0; i < effects_.size(); ++i) {
      f.createGroup("/effects/" + effectNames_[i]);
      effects_[i]->saveState(f, "/effects/" + effectNames_[i]);
    }
    f.flush();
  }
  std::filesystem::rename(tmp, path);
}

void TracerSimulation::loadCheckpoint(const std::string& path) {
  h5::File f(path, h5::File::Mode::ReadOnly);
  if (std::uint64_t(f.readInt64s("/state/seed").at(0)) != settings_.seed) {
    throw InputError(path, "/state/seed", "checkpoint was written with another seed");
  }
  auto x = f.readDoubles("/cloud/x");
  if (x.size() != cloud_.size()) {
    throw InputError(path, "/cloud/x", "checkpoint has " + std::to_string(x.size()) + " tracers, the scene " +
                                           std::to_string(cloud_.size()));
  }
  cloud_.x = std::move(x);
  cloud_.y = f.readDoubles("/cloud/y");
  cloud_.z = f.readDoubles("/cloud/z");
  cloud_.vx = f.readDoubles("/cloud/vx");
  cloud_.vy = f.readDoubles("/cloud/vy");
  cloud_.vz = f.readDoubles("/cloud/vz");
  // The tracers' identities (checkpoints from before the sort by cell: the identity order). A
  // damaged list would send per-tracer results to the wrong tracers: it must be a permutation.
  const std::size_t n = cloud_.size();
  std::vector<std::int64_t> id(n);
  for (std::size_t i = 0; i < n; ++i) id[i] = std::int64_t(i);
  if (f.exists("/cloud/id")) id = f.readInt64s("/cloud/id");
  std::vector<char> seen(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (id.size() != n || id[i] < 0 || id[i] >= std::int64_t(n) || seen[std::size_t(id[i])]) {
      throw InputError(path, "/cloud/id", "must list every tracer id 0.." + std::to_string(n - 1) + " once");
    }
    seen[std::size_t(id[i])] = 1;
    cloud_.id[i] = std::int32_t(id[i]);
  }
  context_->step = f.readInt64s("/state/step").at(0);
  context_->nextTracerCellStep = -1;  // the positions came from the file
  for (std::size_t i = 0; i < effects_.size(); ++i) {
    effects_[i]->loadState(f, "/effects/" + effectNames_[i]);
  }
  loadFrames();
}

void TracerSimulation::writeResults(h5::File& out, nlohmann::json& summary) const {
  out.write("/tracers/x", cloud_.inIdOrder(cloud_.x));
  out.write("/tracers/y", cloud_.inIdOrder(cloud_.y));
  out.write("/tracers/z", cloud_.inIdOrder(cloud_.z));
  summary["tracers"] = cloud_.size();
  summary["particles_per_tracer"] = cloud_.particlesPerTracer;
  for (std::size_t i = 0; i < effects_.size(); ++i) effects_[i]->writeResults(*context_, out, summary);
}

std::vector<std::string> TracerSimulation::writeFigures(const std::string& outDir) const {
  std::vector<std::string> files;
  for (const auto& e : effects_) {
    const auto written = e->writeFigures(*context_, outDir);
    files.insert(files.end(), written.begin(), written.end());
  }
  return files;
}

}  // namespace rcfd
