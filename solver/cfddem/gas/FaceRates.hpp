#pragma once
/// \file FaceRates.hpp
/// The explicit rates of the gas predictor at the staggered faces, advection, viscosity and sources of
/// Eq. (2) (GasAdvection.cpp; the scheme in docs/gas.md): the arithmetic of one face, which
/// GasSolver::faceRate() applies face by face, and the row loop faceRows() (FaceRows.cpp), which applies it
/// to the faces of a grid row whose stencils stay inside the grid in loops the compiler vectorises.
/// FaceRows.cpp is compiled once per kernel variant (core/Isa.hpp); GasSolver calls the one
/// kernelIsa() picks through faceRowsFor().

#include <array>
#include <cstddef>

#include "core/Isa.hpp"
#include "core/IsaNamespace.hpp"

namespace rcfd::gas {

/// van Leer limited slope from the two one-sided differences (0 at an extremum).
inline double limitedSlope(double forward, double backward) {
  const double prod = forward * backward;
  return prod > 0.0 ? 2.0 * prod / (forward + backward) : 0.0;
}

/// Adds to r the advection and viscosity of one axis at a face, Eq. (2): -a dphi/dx by second-order
/// upwind with a van Leer limiter (first order at extrema) from limited values at the two half-points,
/// and nu d2phi/dx2; w0..w4 are the face values at offsets -2..2 along the axis, h its spacing. Both
/// upwind sides are formed and one selected, so a loop over faces stays branch-free.
inline double addAdvectionDiffusion(double r, double a, double w0, double w1, double w2, double w3, double w4,
                                    double h, double nu) {
  const double plusUp = w2 + 0.5 * limitedSlope(w3 - w2, w2 - w1);
  const double minusUp = w1 + 0.5 * limitedSlope(w2 - w1, w1 - w0);
  const double plusDown = w3 - 0.5 * limitedSlope(w4 - w3, w3 - w2);
  const double minusDown = w2 - 0.5 * limitedSlope(w3 - w2, w2 - w1);
  const bool up = a >= 0;
  const double plus = up ? plusUp : plusDown, minus = up ? minusUp : minusDown;
  r -= a * (plus - minus) / h;
  r += nu * (w3 - 2 * w2 + w1) / (h * h);  // alpha grad.tau / (alpha rho)
  return r;
}

/// Adds to r a face's body and source terms: gravity, the explicit force per volume fe over
/// (alpha rho), and the nozzle air entering with the jet velocity (+y), s (u_jet - u) / alpha.
inline double addSources(double r, double gravity, double fe, double sF, double jet, double u, double aF,
                         double rho) {
  return r + gravity + fe / (aF * rho) + sF * (jet - u) / aF;
}

/// Stencil point of the rates: the face value at offset m along e of a face at index x along e is
/// sign * u[face + shift * stride_e] (shift = m inside the grid, a mirror or copy outside).
struct GhostPoint {
  int shift = 0;
  double sign = 1.0;
};

/// What faceRows() reads: the gas solver's fields and tables as plain values, per face axis d.
struct FaceRowInputs {
  const double* u[3] = {};                 ///< face velocities of axis d [m/s]
  const char* kinds[3] = {};               ///< GasSolver::FaceKind of each face of axis d
  char interior = 0;                       ///< GasSolver::Interior
  std::array<int, 3> faceShape[3] = {};    ///< face counts of axis d (FaceApertures::shape)
  std::array<int, 3> cells = {};           ///< the grid's nx, ny, nz
  double spacing[3] = {};                  ///< [m]
  double nu = 0.0, rho = 0.0;              ///< the gas's kinematic viscosity [m2/s] and density [kg/m3]
  double gravity[3] = {};                  ///< [m/s2]
  double jet = 0.0;                        ///< the nozzle jet's velocity (+y) [m/s]
  const GhostPoint* ghost[3][3] = {};      ///< [d][e]: x * 5 + m + 2 (GasSolver::buildStencils())
  const double* alphaNext = nullptr;       ///< alpha_G at the step's end, per cell
  const double* fExplicit = nullptr;       ///< explicit force per volume, 3 per cell [N/m3]
  const double* source = nullptr;          ///< nozzle volume source per cell [1/s]
};

/// The rates of the faces i0 <= i < i1 of row (j, k) of axis d into out (the axis' rate array): faces
/// whose stencils along x stay inside the grid and whose neighbours along d exist; 0 where not interior.
using FaceRows = void (*)(const FaceRowInputs& in, int d, int j, int k, int i0, int i1, double* out);

// The variants; a build defines those builtIsas() lists.
namespace isa_avx2 {
void faceRows(const FaceRowInputs& in, int d, int j, int k, int i0, int i1, double* out);
}
namespace isa_avx512 {
void faceRows(const FaceRowInputs& in, int d, int j, int k, int i0, int i1, double* out);
}
namespace isa_native {
void faceRows(const FaceRowInputs& in, int d, int j, int k, int i0, int i1, double* out);
}

/// The variant compiled for `isa` (one of builtIsas()).
FaceRows faceRowsFor(Isa isa);

}  // namespace rcfd::gas
