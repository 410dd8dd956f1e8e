// deposition: a parcel loses the fraction eta (Eq. 11-14) of its droplets over every sub-step of its
// flight, in the cell of the sub-step's midpoint, for the time it spends on it (the `spray` effect asks
// ParcelDeposition::efficiency() as it moves the parcels, so the deposit does not depend on how many
// cells a parcel crosses in one rCFD step, and a parcel that reaches a wall deposits on its way there).
// alpha_P in Eq. (11) is the tracers' own volume fraction, so deposited droplets always have tracers to
// go to. Droplets are discrete: the droplets stripped in a cell are handed out whole, each to a tracer of
// that cell drawn at random (a fraction of a droplet waits in the cell for the next step); a tracer's
// droplets per real particle are its droplets / (particles per tracer). With one tracer per particle,
// as in the paper, a well-mixed bed thus collects Poisson-distributed droplet counts, as real particles
// do. Parcels with fewer than one droplet left are removed (N_D,min = 1, the paper).
//
// Determinism: the books of the deposits are kept in a fixed order by `spray`; the per-cell carry and the
// random hand-out run in cell and tracer order with counter-based random numbers keyed by (cell, step).
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <random>

#include "core/Errors.hpp"
#include "core/Permutation.hpp"
#include "spray/DepositionEfficiency.hpp"
#include "spray/DueCellScan.hpp"
#include "spray/SprayState.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/StepField.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {

spray::DueCellScan spray::dueCellScanFor(Isa isa) {
  switch (isa) {
#if defined(RCFD_NATIVE_BUILD)
    case Isa::native: return isa_native::tracersInDueCells;
#else
    case Isa::avx2: return isa_avx2::tracersInDueCells;
    case Isa::avx512: return isa_avx512::tracersInDueCells;
#endif
    default: throw RunError(std::string("the deposition's scan has no ") + isaName(isa) + " variant in this build");
  }
}

namespace {

constexpr std::int64_t kPicksPerBinomial = 32;  ///< see DepositionEffect::distribute
/// Whole droplets one cell hands out in one step at most: 2^53, below which whole numbers are exact in
/// double (and far inside int64). Reached only by droplets of a fraction of a micrometre.
constexpr double kMaxDropletsPerHandOut = 9007199254740992.0;

class DepositionEffect final : public TracerEffect, public ParcelDeposition {
 public:
  explicit DepositionEffect(TracerContext& ctx)
      : model_(DepositionModelRegistry::create(ctx.scene.spray.deposition_model)), state_(ctx.spray),
        scanDueCells_(spray::dueCellScanFor(kernelIsa())), constants_(depositionConstants(ctx.scene)) {
    state_->cellDeposit.assign(std::size_t(ctx.grid.cellCount()), 0.0);
    state_->cellPending.assign(std::size_t(ctx.grid.cellCount()), 0.0);
    state_->tracerDroplets.assign(ctx.cloud.size(), 0.0);
    due_.assign(std::size_t(ctx.grid.cellCount()), 0);
    slot_.assign(std::size_t(ctx.grid.cellCount()), -1);
    dueBits_.assign((std::size_t(ctx.grid.cellCount()) + 31) / 32, 0);
    state_->deposition = this;
  }
  ~DepositionEffect() override {
    if (state_->deposition == this) state_->deposition = nullptr;
  }

  std::size_t allocatedBytes() const override {
    return (state_->cellDeposit.capacity() + state_->cellPending.capacity() + state_->tracerDroplets.capacity()) *
               sizeof(double) +
           due_.capacity() * sizeof(std::int64_t) + (slot_.capacity() + dueBits_.capacity()) * sizeof(std::int32_t);
  }

  bool afterMoveBesideMotion() const override { return true; }
  void afterMove(TracerContext& ctx) override {
    collectTouchedCells();
    handOut(ctx);
  }

  void permuteTracers(TracerContext&, const std::vector<std::int32_t>& from) override {
    applyPermutation(state_->tracerDroplets, from);
  }

  void saveState(h5::File& f, const std::string& g) const override {
    f.write(g + "/tracer_droplets", state_->tracerDroplets);
    f.write(g + "/cell_pending", state_->cellPending);
    f.write(g + "/assigned", std::vector<double>{state_->assigned});
  }
  void loadState(const h5::File& f, const std::string& g) override {
    state_->tracerDroplets = f.readDoubles(g + "/tracer_droplets");
    state_->cellPending = f.readDoubles(g + "/cell_pending");
    state_->assigned = f.readDoubles(g + "/assigned").at(0);
  }

 private:
  void beginStep(TracerContext& ctx) override {
    tracerAlpha_ = ctx.tracerAlpha.data();
    // |u_G - u_P| from the step fields the spray parcels and the motion kernel read (float trilinear):
    // 2 x 8 corners in double per sample cost as much as moving the parcels.
    frames_.emplace(ctx.sampler());
    gas_.emplace(ctx.stepVelocity(true, StepFieldLayout::Any), frames_->locator());
    particles_.emplace(ctx.stepVelocity(false), frames_->locator());
    grid_ = &ctx.grid;
  }

  double efficiency(const Eigen::Vector3d& mid, double seconds, std::int32_t& cell) const override {
    cell = std::int32_t(grid_->flatIndexOf(mid));
    const double alphaP = tracerAlpha_[std::size_t(cell)];
    // No tracers, no deposition (eta = 0, Eq. 11): most airborne parcels are above the bed, and the
    // two velocity samples are the dear part.
    if (!(alphaP > 0.0)) return 0.0;
    const DepositionInput in{alphaP, (gas_->sample(mid) - particles_->sample(mid)).norm(), seconds};
    return model_->efficiency(in, constants_);
  }

  /// The cells with new deposits (booked by `spray` as the parcels moved), pending fractions or
  /// droplets waiting from the last step.
  void collectTouchedCells() {
    const auto& s = *state_;
    touched_.assign(s.depositCells.begin(), s.depositCells.end());
    if (!pendingCellsKnown_) {  // first step of a run or of a resume: find cells keeping a fraction
      for (std::size_t c = 0; c < s.cellPending.size(); ++c) {
        if (s.cellPending[c] > 0.0) touched_.push_back(std::int32_t(c));
      }
      pendingCellsKnown_ = true;
    }
    touched_.insert(touched_.end(), waiting_.begin(), waiting_.end());
    std::sort(touched_.begin(), touched_.end());
    touched_.erase(std::unique(touched_.begin(), touched_.end()), touched_.end());
  }

  void handOut(TracerContext& ctx) {
    auto& s = *state_;
    // Whole droplets due per touched cell; the fraction waits. Tiny droplets deposit billions a cell and
    // step (64-bit counts); at most kMaxDropletsPerHandOut, whole numbers exact in double, go out in one
    // step, and anything beyond waits in the cell like the fraction (still in the books as pending).
    bool anyDue = false;
    for (const std::int32_t c : touched_) {
      const double total = s.cellPending[std::size_t(c)] + s.cellDeposit[std::size_t(c)];
      const double whole = ctx.tracerCount[std::size_t(c)] > 0 ? std::min(std::floor(total), kMaxDropletsPerHandOut) : 0.0;
      due_[std::size_t(c)] = std::int64_t(whole);
      s.cellPending[std::size_t(c)] = total - whole;
      anyDue = anyDue || whole > 0.0;
    }
    waiting_.clear();
    for (const std::int32_t c : touched_) {
      if (s.cellPending[std::size_t(c)] > 0.0) waiting_.push_back(c);
    }
    if (!anyDue) return;
    // The cells with droplets due, in cell order, each a slot; then their tracers grouped by slot, in
    // tracer order within a slot: one pass over all tracers in contiguous ranges (in parallel), the
    // few members of each range kept in range order, then a stable counting sort by slot. The order
    // is the same for any thread count.
    slotCells_.clear();
    for (const std::int32_t c : touched_) {
      if (due_[std::size_t(c)] > 0) {
        slot_[std::size_t(c)] = std::int32_t(slotCells_.size());
        slotCells_.push_back(c);
        dueBits_[std::size_t(c) >> 5] |= std::uint32_t(1) << (c & 31);
      }
    }
    const std::size_t slots = slotCells_.size();
    const std::int64_t n = std::int64_t(ctx.cloud.size());
    const bool parallel = n > kParallelThreshold;
    const int threads = parallel ? omp_get_max_threads() : 1;
    const std::int32_t* cellOf = ctx.tracerCell.data();
    const std::int32_t* slotOf = slot_.data();
    const std::uint32_t* dueBits = dueBits_.data();
    found_.resize(std::size_t(threads));
    int team = 1;  // a team may be smaller than asked for (nested inside a calibration's threads)
#pragma omp parallel num_threads(threads) if (parallel)
    {
      const int used = omp_get_num_threads(), t = omp_get_thread_num();
#pragma omp single nowait
      team = used;
      const std::int64_t first = n * t / used, last = n * (t + 1) / used;
      auto& mine = found_[std::size_t(t)];
      mine.clear();
      scanDueCells_(dueBits, cellOf, first, last, mine);
    }
    for (const std::int32_t c : slotCells_) dueBits_[std::size_t(c) >> 5] = 0;
    found_.resize(std::size_t(team));
    slotStart_.assign(slots + 1, 0);
    for (const auto& range : found_) {
      for (const std::int32_t i : range) ++slotStart_[std::size_t(slotOf[cellOf[i]]) + 1];
    }
    for (std::size_t k = 0; k < slots; ++k) slotStart_[k + 1] += slotStart_[k];
    members_.resize(std::size_t(slotStart_[slots]));
    cursor_.assign(slotStart_.begin(), slotStart_.end() - 1);
    for (const auto& range : found_) {
      for (const std::int32_t i : range) members_[std::size_t(cursor_[std::size_t(slotOf[cellOf[i]])]++)] = i;
    }
    // Slots in parallel: each draws from its cell's own stream and writes only its cell's tracers, so
    // the result is the same for any thread count; `assigned` sums whole numbers, exact in any order.
    double assigned = 0.0;
#pragma omp parallel for schedule(dynamic, 16) reduction(+ : assigned) if (parallel)
    for (std::size_t k = 0; k < slots; ++k) {
      const std::int32_t c = slotCells_[k];
      slot_[std::size_t(c)] = -1;
      CounterRng rng(ctx.seed, RngPurpose::Deposition, std::uint64_t(c), std::uint64_t(ctx.step));
      distribute(rng, due_[std::size_t(c)], std::size_t(slotStart_[k]), std::size_t(slotStart_[k + 1]),
                 s.tracerDroplets);
      assigned += double(due_[std::size_t(c)]);
      due_[std::size_t(c)] = 0;
    }
    s.assigned += assigned;
  }

  /// Bit `cell` of a bitmap as 0 or 1 (a signed index: GCC gathers with it, not with an unsigned one).

  /// Hands `droplets` whole droplets to the tracers members_[start, end) with equal probability each: a
  /// multinomial draw. Up to kPicksPerBinomial droplets per tracer: one uniform pick per droplet; more:
  /// sequential binomials, so the cost is bounded by the number of tracers, not of droplets
  /// (compressed-time tests deposit 1e7 per step). Both are exact; the switch sits where their costs
  /// meet (a std::binomial_distribution is set up per tracer, about as dear as 30 picks).
  void distribute(CounterRng& rng, std::int64_t droplets, std::size_t start, std::size_t end,
                  std::vector<double>& collected) const {
    const std::size_t k = end - start;
    if (droplets <= kPicksPerBinomial * std::int64_t(k)) {
      for (std::int64_t d = 0; d < droplets; ++d) {
        const std::size_t pick = std::min(end - 1, start + std::size_t(rng.uniform() * double(k)));
        collected[std::size_t(members_[pick])] += 1.0;
      }
      return;
    }
    std::int64_t left = droplets;
    for (std::size_t m = start; m < end && left > 0; ++m) {
      const std::size_t remaining = end - m;
      std::int64_t take = left;
      if (remaining > 1) {
        CounterUrbg urbg{&rng};
        std::binomial_distribution<std::int64_t> binomial(left, 1.0 / double(remaining));
        take = binomial(urbg);
      }
      collected[std::size_t(members_[m])] += double(take);
      left -= take;
    }
  }

  /// CounterRng as a UniformRandomBitGenerator for the standard distributions.
  struct CounterUrbg {
    using result_type = std::uint64_t;
    CounterRng* rng;
    static constexpr result_type min() { return 0; }
    static constexpr result_type max() { return ~result_type(0); }
    result_type operator()() { return rng->nextU64(); }
  };

  std::unique_ptr<DepositionModel> model_;
  std::shared_ptr<SprayState> state_;
  spray::DueCellScan scanDueCells_;  ///< the tracers of the cells with droplets due, in the variant kernelIsa() picks
  DepositionConstants constants_;
  // Of the step the parcels are moving in (beginStep):
  const CartesianGrid* grid_ = nullptr;
  const float* tracerAlpha_ = nullptr;
  std::optional<FrameSampler> frames_;
  std::optional<StepFieldSampler> gas_, particles_;
  std::vector<std::int64_t> due_;       ///< whole droplets due per cell this step
  std::vector<std::int32_t> touched_;   ///< cells with new or pending droplets this step
  std::vector<std::int32_t> waiting_;   ///< cells keeping a fraction of a droplet
  std::vector<std::int32_t> members_;     ///< tracers of the cells with droplets due, grouped by cell
  std::vector<std::int32_t> slot_;        ///< per cell: its slot this step, or -1
  std::vector<std::uint32_t> dueBits_;    ///< one bit per cell: set for the cells with droplets due
  std::vector<std::int32_t> slotCells_;   ///< cells with droplets due, in cell order
  std::vector<std::int64_t> slotStart_;   ///< members_ of slot k: [slotStart_[k], slotStart_[k + 1])
  std::vector<std::int64_t> cursor_;      ///< per slot: the next write position in members_
  std::vector<std::vector<std::int32_t>> found_;  ///< per thread: members found in its range of tracers
  bool pendingCellsKnown_ = false;
};

const bool registered = TracerEffectRegistry::add(
    "deposition", {"spray", "tracer_volume_fraction"}, 51,
    "Eq. (11)-(14): droplets deposit on the tracers of the parcel's cell (spray.deposition_model)",
    [](TracerContext& c) { return std::make_unique<DepositionEffect>(c); });

}  // namespace
}  // namespace rcfd
