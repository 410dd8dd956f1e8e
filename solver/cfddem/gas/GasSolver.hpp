#pragma once
/// \file GasSolver.hpp
/// The gas phase of the built-in CFD-DEM: volume-averaged incompressible Navier-Stokes, the paper's
/// model A, Eq. (1)-(2), on the scene's uniform Cartesian grid. Staggered (MAC) velocities on faces,
/// cut cells by face apertures (FaceApertures.hpp), fractional-step projection with a pressure Poisson
/// equation solved by preconditioned CG (PressureSolver.hpp). docs/gas.md describes the discretisation.
///
/// Conventions for the coupling:
///  - alpha_G is per cell, the gas fraction of the cell's *open* volume (1 in a particle-free cut cell).
///  - The drag source is a force per unit cell volume acting on the gas, f = -beta (u_G - u_P) + f_expl
///    [N/m3], i.e. the last term of Eq. (2) times rho_G: alpha_G sum_i F_i,drag / V. beta >= 0 [kg/(m3 s)]
///    is treated implicitly.
///  - p is the pressure in Pa (not divided by rho_G), relative to the outlet (p = 0 at the top).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cfddem/gas/FaceApertures.hpp"
#include "cfddem/gas/FaceRates.hpp"
#include "cfddem/gas/PressureSolver.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/CartesianGrid.hpp"
#include "scene/Scene.hpp"

namespace rcfd::h5 {
class File;
}

namespace rcfd::gas {

/// Face (and cell) loops of the gas step below this size run serially: fork/join and barrier costs
/// dominate. Every such loop writes each face or cell once, so the split never changes the bits.
inline constexpr std::size_t kParallelFaces = 10000;

/// Settings that are not in the scene (solver choices and verification set-ups).
struct GasOptions {
  int refactorInterval = 20;          ///< steps between preconditioner rebuilds (IC, mg) while the matrix drifts
  int maxPressureIterations = 2000;
  /// The front and back walls (z = 0, z = depth) without friction: plane flow in a slice. Default
  /// no-slip, as in the real apparatus.
  bool slipFrontBack = false;
  /// The side walls of a box (x = +-size.x/2) without friction (verification of uniform streams).
  bool slipSideWalls = false;
  /// Box apparatus only: the whole bottom face y = 0 is an inlet carrying process.gas_flow_rate
  /// (verification channels and packed beds; the box of the scene has walls all round otherwise).
  bool boxBottomInlet = false;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< body acceleration on the gas [m/s2]
};

/// Discrete continuity residual of the last step, Eq. (1) per cell:
/// r_c = V phi_c dalpha/dt + sum_f A_f a_f alpha_f u_f - V s_c (s: nozzle source) [m3/s].
struct DivergenceResidual {
  double relative = 0.0;  ///< |r|_2 / |F|_2, F_c = sum_f |A a alpha u_f| + V|s_c| + V phi |dalpha/dt| [-]
  double maxAbs = 0.0;    ///< max_c |r_c| / V_c [1/s]
  /// |sum_c r_c| / (inlet flow + nozzle flow): the domain's mass balance (what enters leaves or is
  /// stored) relative to the gas fed (sum_c V phi |dalpha/dt| without a feed), which a small |r|_2 does
  /// not bound tightly; the scale is at least the cells' root-mean-square F_c and a millionth of the
  /// scene's full flow (a feed of 0 at the start of a ramp) [-]
  double net = 0.0;
};

struct GasStepStats {
  double dt = 0.0;               ///< time step taken [s]
  int pressureIterations = 0;
  double courant = 0.0;          ///< dt * max_cell sum_d |u_d| / h_d after the step [-]
  DivergenceResidual divergence;
};

class GasSolver {
 public:
  /// Builds the grid topology (face apertures, active cells, inlet/outlet/nozzle faces). Throws
  /// InputError naming the scene field when the set-up cannot carry a flow (no outlet, a nozzle outside
  /// the open region, an inlet flow with no inlet). Keeps references to scene and apparatus: they must
  /// outlive the solver.
  GasSolver(const Scene& scene, const Apparatus& apparatus, const CartesianGrid& grid,
            GasOptions options = {});
  ~GasSolver();

  /// alpha_G per cell for the next step; dalpha/dt over that step is (alpha_new - alpha_old) / dt.
  /// Throws RunError on a value that is not finite or outside (0, 1] (index and value in the message).
  void setGasFraction(const std::vector<double>& alphaG);
  /// The same with the coupling's own dalpha/dt [1/s] for the next step.
  void setGasFraction(const std::vector<double>& alphaG, const std::vector<double>& dAlphaDt);
  /// Implicit drag: f = -beta (u_G - u_P) per unit volume; beta [kg/(m3 s)] >= 0 per cell.
  void setDragSource(const std::vector<double>& beta, const std::vector<Eigen::Vector3d>& particleVelocity);
  /// Explicit momentum source per unit volume [N/m3] per cell (added to the implicit drag).
  void setExplicitSource(const std::vector<Eigen::Vector3d>& force);

  /// Advances by one step of at most maxDt (and the scene's CFL and max_time_step); returns the dt taken.
  double step(double maxDt);
  /// The step step() would take without a caller's bound: the scene's max_time_step, the CFL limit of
  /// the current velocities (and the nozzle jet), the viscous and nozzle-source limits [s]. Depends on
  /// the alpha_G set for the next step.
  double stableTimeStep() const;
  /// Scales the inlet velocity and the nozzle source (and jet velocity) by factor in [0, 1] from the
  /// next step on: the database job ramps the gas up. Throws RunError outside [0, 1].
  void setFlowFactor(double factor);
  double flowFactor() const { return flowFactor_; }

  /// Whole state (face velocities, pressure and its warm start, alpha_G, sources, clock) into / from
  /// group of a checkpoint file. The pressure preconditioner is rebuilt at the first step after a
  /// load (so a continued run agrees with an uninterrupted one to the pressure tolerance, not bitwise).
  void saveState(h5::File& file, const std::string& group) const;
  void loadState(const h5::File& file, const std::string& group);
  const GasStepStats& lastStep() const { return last_; }
  double time() const { return time_; }

  /// Velocity interpolated from the faces (trilinear per component; zero in walls) [m/s].
  Eigen::Vector3d velocityAt(const Eigen::Vector3d& p) const;
  /// grad p interpolated from the open faces (walls excluded) [Pa/m]: F_p = -V_i grad p on a particle.
  Eigen::Vector3d pressureGradientAt(const Eigen::Vector3d& p) const;
  /// Cell-centred velocity (mean of the two faces per axis; zero in closed cells), 3 per cell [m/s].
  std::vector<Eigen::Vector3d> cellVelocity() const;
  /// Cell pressure [Pa] (0 in closed cells).
  const std::vector<double>& pressure() const { return p_; }
  /// Area-averaged pressure of the cells above the inlet faces minus that at the outlet (0) [Pa].
  double pressureDrop() const;
  /// Net volume flux out of the domain through inlet and outlet faces, sum A a alpha u . n [m3/s].
  double netOutflow() const;
  /// Volume flux through the inlet faces into the domain [m3/s].
  double inletFlow() const;
  /// Volume injected by the nozzle source [m3/s].
  double nozzleFlow() const;
  /// Sum over cells of V phi dalpha/dt of the last step [m3/s].
  double storageRate() const;

  const CartesianGrid& grid() const { return grid_; }
  const std::vector<double>& openFraction() const { return phi_; }
  const std::vector<char>& activeCells() const { return active_; }
  const FaceApertures& apertures() const { return ap_; }
  /// Face velocities of axis d (layout of FaceApertures) [m/s].
  const std::vector<double>& faceVelocity(int d) const { return u_[std::size_t(d)]; }
  double inletVelocity() const { return inletVelocity_; }

 /// What a face is for the solver: closed (zero velocity), interior (momentum solved), inlet (fixed
  /// velocity), outlet (pressure boundary).
  enum FaceKind : char { Closed = 0, Interior, Inlet, Outlet };
  const std::vector<char>& faceKinds(int d) const { return kind_[std::size_t(d)]; }
  /// alpha_G of cell c in the current state [-].
  double gasFractionOf(std::size_t c) const { return alpha_[c]; }

 private:
  std::size_t faceIndex(int d, int i, int j, int k) const {
    const auto& s = ap_.shape[std::size_t(d)];
    return (std::size_t(k) * s[1] + j) * s[0] + i;
  }
  void buildTopology();
  void buildNozzle();
  double chooseDt(double maxDt) const;
  double convectiveRate() const;
  void explicitRates(const std::array<std::vector<double>, 3>& u, std::array<std::vector<double>, 3>& rate) const;
  /// Tabulates the ghost values of the rates' stencils and the faces near baffles (GasAdvection.cpp).
  void buildStencils();
  /// The explicit rate of face (i, j, k) of axis d (0 for a face that is not interior).
  double faceRate(const std::array<std::vector<double>, 3>& u, int d, int i, int j, int k) const;
  /// Whether a baffle (thin plate) closes the way from face idx of axis d to its neighbour at +e.
  bool baffleAhead(int d, int e, std::array<int, 3> idx) const;
  /// Stencil values v[0..4] (offsets -2..2 along e of face idx, axis d): no-slip mirror at baffles.
  void mirrorAtBaffles(int d, int e, const std::array<int, 3>& idx, double v[5]) const;
  double faceAlpha(int d, std::size_t f, int i, int j, int k) const;
  void project(double dt, const std::array<std::vector<double>, 3>& diag);
  /// Sets up matrix_'s sparsity and the faces' slots in it (GasProjection.cpp).
  void buildMatrixPattern();
  /// Pressure unknowns of the cells below (lo, along d) and above (hi) face (i, j, k) of axis d; -1
  /// outside the grid or for an inactive cell.
  std::array<int, 2> faceUnknowns(int d, int i, int j, int k) const;
  /// Calls visit(d, i, j, k, face index) for every face of every axis, x fastest.
  template <class Visit>
  void forEachFace(Visit&& visit) const {
    for (int d = 0; d < 3; ++d) {
      const auto& s = ap_.shape[std::size_t(d)];
      for (int k = 0; k < s[2]; ++k)
        for (int j = 0; j < s[1]; ++j)
          for (int i = 0; i < s[0]; ++i) visit(d, i, j, k, faceIndex(d, i, j, k));
    }
  }
  /// Calls visit(d, face, upperCell) for the six faces of cell (i, j, k) that are not closed, axis by
  /// axis, the lower face first: the order in which a scatter over all faces (forEachFace) reaches
  /// them, so sums gathered per cell equal the scatter's. upperCell: the cell lies above the face.
  template <class Visit>
  void forEachOpenFaceOf(int i, int j, int k, Visit&& visit) const {
    for (int d = 0; d < 3; ++d) {
      int hi[3] = {i, j, k};
      ++hi[d];
      const std::size_t lower = faceIndex(d, i, j, k), upper = faceIndex(d, hi[0], hi[1], hi[2]);
      if (kind_[std::size_t(d)][lower] != Closed) visit(d, lower, true);
      if (kind_[std::size_t(d)][upper] != Closed) visit(d, upper, false);
    }
  }
  void correct(const std::array<std::vector<double>, 3>& diag);
  /// pressureGradient_ from p_ (after every change of p_).
  void updatePressureGradient();
  /// gasArea_ for the alpha_G of the step being projected.
  void computeGasAreas();
  /// The continuity residual of Eq. (1) with the current face velocities and gasArea_.
  DivergenceResidual divergence() const;
  void checkAlpha(const std::vector<double>& alpha, const char* what) const;

  const Scene& scene_;
  const Apparatus& apparatus_;
  CartesianGrid grid_;
  GasOptions options_;
  FaceApertures ap_;
  std::array<std::vector<char>, 3> kind_;
  std::array<std::vector<double>, 3> u_;
  std::vector<double> phi_;       ///< open fraction per cell
  std::vector<char> active_;      ///< cell is open and connected to the outlet
  std::vector<int> unknown_;      ///< pressure unknown per cell, -1 for inactive
  std::vector<double> alpha_, alphaNext_, dAlphaDt_;
  bool givenRate_ = false;
  bool matrixDirty_ = true;  ///< alpha_G changed since the pressure matrix was built
  bool hasDrag_ = false;     ///< some beta > 0: the matrix changes with dt
  std::vector<double> beta_;
  std::vector<Eigen::Vector3d> uParticle_, fExplicit_;
  std::vector<double> source_;    ///< nozzle volume source per unit volume s_c [1/s]
  double nozzleJetVelocity_ = 0.0;
  double inletVelocity_ = 0.0;
  std::vector<double> source0_;   ///< nozzle source at flow factor 1
  double nozzleJetVelocity0_ = 0.0, inletVelocity0_ = 0.0;
  double flowFactor_ = 1.0;
  std::vector<double> p_;
  /// grad p on the interior and outlet faces of each axis [Pa/m] (0 on the others): computed once per
  /// pressure solve, then interpolated at every parcel by pressureGradientAt().
  std::array<std::vector<double>, 3> pressureGradient_;
  Eigen::VectorXd q_;             ///< p dt / rho of the last solve (warm start)
  std::unique_ptr<PressureSolver> pressureSolver_;
  PressureSolver::Matrix matrix_;  ///< the pressure matrix: pattern fixed by the topology, values refilled
  /// Per axis and face: indices in matrix_'s values of (lo, lo), (hi, hi), (lo, hi), (hi, lo) of an
  /// interior face, [0] = (lo, lo) of an outlet face.
  std::array<std::vector<std::array<int, 4>>, 3> matrixSlot_;
  FaceRows faceRows_;  ///< the row loop of explicitRates(), in the variant kernelIsa() picks
  std::array<std::array<std::vector<GhostPoint>, 3>, 3> ghost_;  ///< [d][e][x * 5 + m + 2]
  std::array<std::vector<std::uint8_t>, 3> nearBaffle_;          ///< [d][face]: bit e, empty without baffles
  /// Per axis and face, its gas area A a alpha_G [m2] (0 where closed): computed once per projection
  /// (alpha_G does not change within it) for the assembly and every divergence check.
  std::array<std::vector<double>, 3> gasArea_;
  std::vector<std::pair<int, std::size_t>> inletFaces_;  ///< (axis, face) of the inlet faces, in face order (topology)
  mutable std::array<std::vector<double>, 2> divergenceScratch_;  ///< residual and scale per cell
  GasStepStats last_;
  double time_ = 0.0;
  double lastDt_ = 0.0;
};

}  // namespace rcfd::gas
