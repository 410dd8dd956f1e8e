// GasSolver: set-up, time step and projection (GasSolver.hpp; queries in GasQueries.cpp).

#include "cfddem/gas/GasSolver.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/Errors.hpp"

namespace rcfd::gas {
namespace {

/// Safety factor on the explicit-diffusion stability bound dt <= 1 / (2 nu sum_d 1/h_d^2).
constexpr double kViscousSafety = 0.9;
/// Safety factor on the explicit nozzle-source bound dt <= alpha / s.
constexpr double kSourceSafety = 0.5;

std::string cellText(const CartesianGrid& g, std::size_t c) {
  const auto ijk = g.cellIjk(std::int64_t(c));
  std::ostringstream s;
  s << "cell " << c << " (i, j, k) = (" << ijk[0] << ", " << ijk[1] << ", " << ijk[2] << ")";
  return s.str();
}

}  // namespace

GasSolver::GasSolver(const Scene& scene, const Apparatus& apparatus, const CartesianGrid& grid,
                     GasOptions options)
    : scene_(scene), apparatus_(apparatus), grid_(grid), options_(std::move(options)),
      faceRows_(faceRowsFor(kernelIsa())) {
  pressureSolver_ = std::make_unique<PressureSolver>(
      PreconditionerRegistry::createAt("scene", "/gas/pressure_preconditioner", scene_.gas.pressure_preconditioner),
      options_.refactorInterval);
  const std::size_t n = std::size_t(grid_.cellCount());
  phi_ = openFractions(apparatus_, grid_);
  alpha_.assign(n, 1.0);
  alphaNext_ = alpha_;
  dAlphaDt_.assign(n, 0.0);
  beta_.assign(n, 0.0);
  uParticle_.assign(n, Eigen::Vector3d::Zero());
  fExplicit_.assign(n, Eigen::Vector3d::Zero());
  source_.assign(n, 0.0);
  p_.assign(n, 0.0);
  ap_ = computeFaceApertures(apparatus_, grid_);
  buildTopology();
  buildStencils();
  buildNozzle();
  updatePressureGradient();
  source0_ = source_;
  inletVelocity0_ = inletVelocity_;
  nozzleJetVelocity0_ = nozzleJetVelocity_;
}

GasSolver::~GasSolver() = default;

void GasSolver::buildTopology() {
  const auto n = grid_.shape;
  const std::size_t cells = std::size_t(grid_.cellCount());
  const bool box = scene_.apparatus.type == ApparatusSpec::Type::Box;
  if (options_.boxBottomInlet && box) {
    const auto& s = ap_.shape[1];
    for (int k = 0; k < s[2]; ++k)
      for (int i = 0; i < s[0]; ++i) ap_.open[1][faceIndex(1, i, 0, k)] = 1.0;
  }
  for (int d = 0; d < 3; ++d) {
    kind_[std::size_t(d)].assign(ap_.open[std::size_t(d)].size(), Closed);
    u_[std::size_t(d)].assign(ap_.open[std::size_t(d)].size(), 0.0);
  }
  // Flood fill from the cells below open outlet faces through open faces between open cells: cells
  // not reached (enclosed pockets, zero-aperture slivers) have no pressure level and stay closed.
  active_.assign(cells, 0);
  std::vector<std::size_t> stack;
  for (int k = 0; k < n[2]; ++k)
    for (int i = 0; i < n[0]; ++i) {
      const std::size_t c = std::size_t(grid_.flatIndex(i, n[1] - 1, k));
      if (ap_.open[1][faceIndex(1, i, n[1], k)] > 0 && phi_[c] > 0 && !active_[c]) {
        active_[c] = 1;
        stack.push_back(c);
      }
    }
  if (stack.empty())
    throw InputError("scene", box ? "/apparatus/outlet_top" : "/apparatus",
                     "the gas solver needs an outlet at the top (outlet_top: true for a box)");
  while (!stack.empty()) {
    const std::size_t c = stack.back();
    stack.pop_back();
    const auto ijk = grid_.cellIjk(std::int64_t(c));
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        auto nb = ijk;
        nb[std::size_t(d)] += side ? 1 : -1;
        if (nb[std::size_t(d)] < 0 || nb[std::size_t(d)] >= n[std::size_t(d)]) continue;
        auto fi = ijk;
        fi[std::size_t(d)] += side;
        if (ap_.open[std::size_t(d)][faceIndex(d, fi[0], fi[1], fi[2])] <= 0) continue;
        const std::size_t m = std::size_t(grid_.flatIndex(nb[0], nb[1], nb[2]));
        if (phi_[m] > 0 && !active_[m]) {
          active_[m] = 1;
          stack.push_back(m);
        }
      }
  }
  unknown_.assign(cells, -1);
  int count = 0;
  for (std::size_t c = 0; c < cells; ++c)
    if (active_[c]) unknown_[c] = count++;
  q_ = Eigen::VectorXd::Zero(count);
  std::vector<std::array<int, 3>> cellOf;
  cellOf.reserve(std::size_t(count));
  for (std::size_t c = 0; c < cells; ++c)
    if (active_[c]) cellOf.push_back(grid_.cellIjk(std::int64_t(c)));
  pressureSolver_->setCells(std::move(cellOf));

  // Face kinds. Grid-boundary faces are open only at y = 0 (inlet) and at the top (outlet).
  double inletArea = 0.0;
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) {
          const std::size_t f = faceIndex(d, i, j, k);
          if (ap_.open[std::size_t(d)][f] <= 0) continue;
          const std::array<int, 3> hi{i, j, k};
          auto lo = hi;
          lo[std::size_t(d)] -= 1;
          const bool hasLo = lo[std::size_t(d)] >= 0, hasHi = hi[std::size_t(d)] < n[std::size_t(d)];
          const bool loOpen = hasLo && active_[std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]))];
          const bool hiOpen = hasHi && active_[std::size_t(grid_.flatIndex(hi[0], hi[1], hi[2]))];
          char kind = Closed;
          if (hasLo && hasHi) kind = loOpen && hiOpen ? Interior : Closed;
          else if (d == 1 && !hasLo && hiOpen) kind = Inlet;
          else if (d == 1 && !hasHi && loOpen) kind = Outlet;
          kind_[std::size_t(d)][f] = kind;
          if (kind == Inlet) inletArea += ap_.open[1][f] * grid_.spacing.x() * grid_.spacing.z();
        }
  }
  const double q = scene_.process.gas_flow_rate;
  if (q > 0 && inletArea <= 0)
    throw InputError("scene", box ? "/effects" : "/process/gas_flow_rate",
                     "a gas flow of " + std::to_string(q) + " m3/s needs an inlet, but the apparatus has none" +
                         std::string(box ? ": a box's bottom is a wall; the effect gas needs the inlet slot of a "
                                           "prismatic_spouted_bed"
                                         : ""));
  // The scene gives the flow through its own slot (a thin slice gives the slice's share): the
  // superficial inlet velocity is that flow over the slot area, inlet_width * depth.
  inletVelocity_ = inletArea > 0 ? q / inletArea : 0.0;
  for (std::size_t f = 0; f < kind_[1].size(); ++f)
    if (kind_[1][f] == Inlet) u_[1][f] = inletVelocity_;
  inletFaces_.clear();
  for (int d = 0; d < 3; ++d)
    for (std::size_t f = 0; f < kind_[std::size_t(d)].size(); ++f)
      if (kind_[std::size_t(d)][f] == Inlet) inletFaces_.push_back({d, f});
}

void GasSolver::buildNozzle() {
  const double q = scene_.process.atomisation_flow_rate;
  if (q <= 0) return;
  const Eigen::Vector3d np = scene_.spray.nozzle_position;
  const double r = 0.5 * scene_.spray.nozzle_diameter;
  const Eigen::Vector3d h = grid_.spacing, o = grid_.origin;
  // The row of cells just above the nozzle tip (the tip at y = 0 injects into the first row).
  const int j = std::clamp(int(std::floor((np.y() - o.y()) / h.y() + 1e-9)), 0, grid_.shape[1] - 1);
  // Weight of each cell: the nozzle disk's area in the cell's x-z rectangle (sampled on a fine
  // lattice of the disk), times the cell's open fraction.
  constexpr int kSamples = 40;
  std::vector<double> weight(std::size_t(grid_.cellCount()), 0.0);
  double total = 0.0;
  for (int a = 0; a < kSamples; ++a)
    for (int b = 0; b < kSamples; ++b) {
      const double x = np.x() - r + (a + 0.5) * 2 * r / kSamples, z = np.z() - r + (b + 0.5) * 2 * r / kSamples;
      if ((x - np.x()) * (x - np.x()) + (z - np.z()) * (z - np.z()) > r * r) continue;
      const Eigen::Vector3d s(x, o.y() + (j + 0.5) * h.y(), z);
      const std::size_t c = std::size_t(grid_.flatIndexOf(s));
      if (!active_[c]) continue;
      weight[c] += phi_[c];
      total += phi_[c];
    }
  if (total <= 0)
    throw InputError("scene", "/spray/nozzle_position",
                     "the atomisation air cannot enter: no open cell of the gas grid lies above the nozzle disk");
  for (std::size_t c = 0; c < weight.size(); ++c)
    if (weight[c] > 0) source_[c] = q * weight[c] / total / grid_.cellVolume();
  // The jet leaves the nozzle opening (its diameter is the scene's nozzle_diameter) upwards.
  nozzleJetVelocity_ = q / (std::numbers::pi * r * r);
}

void GasSolver::checkAlpha(const std::vector<double>& alpha, const char* what) const {
  if (alpha.size() != std::size_t(grid_.cellCount()))
    throw RunError(std::string("gas solver: ") + what + " has " + std::to_string(alpha.size()) +
                   " values, the grid has " + std::to_string(grid_.cellCount()) + " cells");
  for (std::size_t c = 0; c < alpha.size(); ++c) {
    const double a = alpha[c];
    if (!std::isfinite(a) || a <= 0.0 || a > 1.0 + 1e-12) {
      std::ostringstream s;
      s << "gas solver: " << what << " = " << a << " at " << cellText(grid_, c)
        << " is outside the allowed range (0, 1] (finite, gas volume fraction of the open volume)";
      throw RunError(s.str());
    }
  }
}

void GasSolver::setGasFraction(const std::vector<double>& alphaG) {
  checkAlpha(alphaG, "alpha_G");
  alphaNext_ = alphaG;
  givenRate_ = false;
  matrixDirty_ = true;
}

void GasSolver::setGasFraction(const std::vector<double>& alphaG, const std::vector<double>& dAlphaDt) {
  checkAlpha(alphaG, "alpha_G");
  if (dAlphaDt.size() != alphaG.size()) throw RunError("gas solver: dalpha_G/dt has the wrong size");
  for (std::size_t c = 0; c < dAlphaDt.size(); ++c)
    if (!std::isfinite(dAlphaDt[c]))
      throw RunError("gas solver: dalpha_G/dt is not finite at " + cellText(grid_, c));
  alphaNext_ = alphaG;
  dAlphaDt_ = dAlphaDt;
  givenRate_ = true;
  matrixDirty_ = true;
}

void GasSolver::setDragSource(const std::vector<double>& beta, const std::vector<Eigen::Vector3d>& uP) {
  if (beta.size() != alpha_.size() || uP.size() != alpha_.size())
    throw RunError("gas solver: drag source has the wrong size");
  for (std::size_t c = 0; c < beta.size(); ++c)
    if (!std::isfinite(beta[c]) || beta[c] < 0 || !uP[c].allFinite())
      throw RunError("gas solver: drag coefficient beta must be finite and >= 0, u_P finite; " +
                     std::to_string(beta[c]) + " at " + cellText(grid_, c));
  beta_ = beta;
  uParticle_ = uP;
  hasDrag_ = std::any_of(beta_.begin(), beta_.end(), [](double b) { return b > 0; });
  matrixDirty_ = true;
}

void GasSolver::setExplicitSource(const std::vector<Eigen::Vector3d>& force) {
  if (force.size() != alpha_.size()) throw RunError("gas solver: explicit source has the wrong size");
  for (std::size_t c = 0; c < force.size(); ++c)
    if (!force[c].allFinite()) throw RunError("gas solver: explicit source not finite at " + cellText(grid_, c));
  fExplicit_ = force;
}

double GasSolver::faceAlpha(int d, std::size_t f, int i, int j, int k) const {
  std::array<int, 3> hi{i, j, k}, lo{i, j, k};
  lo[std::size_t(d)] -= 1;
  const char kind = kind_[std::size_t(d)][f];
  if (kind == Interior)
    return 0.5 * (alphaNext_[std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]))] +
                  alphaNext_[std::size_t(grid_.flatIndex(hi[0], hi[1], hi[2]))]);
  if (kind == Inlet) return alphaNext_[std::size_t(grid_.flatIndex(hi[0], hi[1], hi[2]))];
  if (kind == Outlet) return alphaNext_[std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]))];
  return 0.0;
}

double GasSolver::chooseDt(double maxDt) const {
  const double rate = convectiveRate();  // max over cells of sum_d |u_d| / h_d
  const Eigen::Vector3d h = grid_.spacing;
  double dt = std::min(maxDt, scene_.gas.max_time_step);
  if (rate > 0) dt = std::min(dt, scene_.gas.cfl / rate);
  const double nu = scene_.gas.kinematic_viscosity;
  const double invH2 = 1 / (h.x() * h.x()) + 1 / (h.y() * h.y()) + 1 / (h.z() * h.z());
  if (nu > 0) dt = std::min(dt, kViscousSafety / (2 * nu * invH2));
  double sMax = 0.0;
  for (std::size_t c = 0; c < source_.size(); ++c)
    if (source_[c] > 0) sMax = std::max(sMax, source_[c] / alphaNext_[c]);
  if (sMax > 0) dt = std::min(dt, kSourceSafety / sMax);
  return dt;
}

double GasSolver::convectiveRate() const {
  // Per cell: the larger |u| of its two faces per axis over h, summed over the axes (the nozzle's jet
  // velocity counts in the cells it enters). The CFL number is a property of a cell: the maximum of
  // this sum, not the sum of each axis' maximum over the whole domain (which pairs the jet's u_y with
  // some other cell's u_x).
  const Eigen::Vector3d h = grid_.spacing;
  const auto n = grid_.shape;
  double rate = 0.0;
  // A maximum: the same for any order of the cells, so for any number of threads.
#pragma omp parallel for collapse(2) reduction(max : rate) schedule(static) if (alpha_.size() > kParallelFaces)
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const std::size_t c = std::size_t(grid_.flatIndex(i, j, k));
        if (!active_[c]) continue;
        const double ux = std::max(std::abs(u_[0][faceIndex(0, i, j, k)]), std::abs(u_[0][faceIndex(0, i + 1, j, k)]));
        double uy = std::max(std::abs(u_[1][faceIndex(1, i, j, k)]), std::abs(u_[1][faceIndex(1, i, j + 1, k)]));
        if (source_[c] > 0) uy = std::max(uy, nozzleJetVelocity_);
        const double uz = std::max(std::abs(u_[2][faceIndex(2, i, j, k)]), std::abs(u_[2][faceIndex(2, i, j, k + 1)]));
        rate = std::max(rate, ux / h.x() + uy / h.y() + uz / h.z());
      }
  return rate;
}

double GasSolver::step(double maxDt) {
  if (!(maxDt > 0)) throw RunError("gas solver: step(maxDt) needs maxDt > 0");
  const double dt = chooseDt(maxDt);
  const std::size_t cells = alpha_.size();
  if (!givenRate_)
    for (std::size_t c = 0; c < cells; ++c) dAlphaDt_[c] = (alphaNext_[c] - alpha_[c]) / dt;
  // The inlet prescribes the superficial velocity: the gas flux stays the scene's rate whatever alpha_G.
  for (int k = 0; k < ap_.shape[1][2]; ++k)
    for (int i = 0; i < ap_.shape[1][0]; ++i) {
      const std::size_t f = faceIndex(1, i, 0, k);
      if (kind_[1][f] == Inlet) u_[1][f] = inletVelocity_ / alphaNext_[std::size_t(grid_.flatIndex(i, 0, k))];
    }

  // Predictor: SSP-RK2 (Heun) on advection, viscosity and explicit sources.
  std::array<std::vector<double>, 3> rate, u1 = u_, diag;
  for (int d = 0; d < 3; ++d) rate[std::size_t(d)].resize(u_[std::size_t(d)].size());
  explicitRates(u_, rate);
  for (int d = 0; d < 3; ++d)
    for (std::size_t f = 0; f < u1[std::size_t(d)].size(); ++f) u1[std::size_t(d)][f] += dt * rate[std::size_t(d)][f];
  explicitRates(u1, rate);
  const double rho = scene_.gas.density;
  for (int d = 0; d < 3; ++d) {
    const auto& s = ap_.shape[std::size_t(d)];
    auto& ud = u_[std::size_t(d)];
    diag[std::size_t(d)].assign(ud.size(), 1.0);
    // Each face is its own update (as in correct()): any split over threads gives the same bits.
#pragma omp parallel for collapse(2) schedule(static) if (ud.size() > kParallelFaces)
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) {
          const std::size_t f = faceIndex(d, i, j, k);
          if (kind_[std::size_t(d)][f] != Interior) continue;
          double v = 0.5 * (ud[f] + u1[std::size_t(d)][f] + dt * rate[std::size_t(d)][f]);
          // Implicit drag: (u - u_a)/dt = -beta/(alpha rho) (u - u_P), Eq. (2) last term.
          std::array<int, 3> lo{i, j, k};
          lo[std::size_t(d)] -= 1;
          const std::size_t cl = std::size_t(grid_.flatIndex(lo[0], lo[1], lo[2]));
          const std::size_t ch = std::size_t(grid_.flatIndex(i, j, k));
          if (beta_[cl] > 0 || beta_[ch] > 0) {
            // The face carries the mean of its two cells' f / (alpha rho) with the cell velocities
            // u_c = alpha_f u_f / alpha_c (same flux), so the pressure difference across a bed is the
            // sum of its cells' drag even where alpha_G jumps.
            const double aF = 0.5 * (alphaNext_[cl] + alphaNext_[ch]);
            const double kF = 0.5 * aF * (beta_[cl] / (alphaNext_[cl] * alphaNext_[cl]) +
                                          beta_[ch] / (alphaNext_[ch] * alphaNext_[ch])) / rho;
            const double target = 0.5 * (beta_[cl] * uParticle_[cl][d] / alphaNext_[cl] +
                                         beta_[ch] * uParticle_[ch][d] / alphaNext_[ch]) / rho;
            v = (v + dt * target) / (1 + dt * kF);
            diag[std::size_t(d)][f] = 1 / (1 + dt * kF);
          }
          ud[f] = v;
        }
  }
  // Outlet: zero-gradient predictor from the face below; the projection then balances the mass.
  {
    const auto& s = ap_.shape[1];
    for (int k = 0; k < s[2]; ++k)
      for (int i = 0; i < s[0]; ++i) {
        const std::size_t f = faceIndex(1, i, s[1] - 1, k), below = faceIndex(1, i, s[1] - 2, k);
        if (kind_[1][f] == Outlet) u_[1][f] = kind_[1][below] == Interior ? u_[1][below] : 0.0;
      }
  }
  project(dt, diag);
  alpha_ = alphaNext_;
  givenRate_ = false;
  time_ += dt;
  lastDt_ = dt;
  last_.dt = dt;
  last_.courant = dt * convectiveRate();
  for (int d = 0; d < 3; ++d)
    for (double v : u_[std::size_t(d)])
      if (!std::isfinite(v))
        throw RunError("gas solver: the velocity became non-finite at t = " + std::to_string(time_) +
                       " s (dt = " + std::to_string(dt) + " s)");
  return dt;
}

}  // namespace rcfd::gas
