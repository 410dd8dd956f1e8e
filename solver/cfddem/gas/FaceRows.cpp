// The gas predictor's explicit rates on a row of faces (FaceRates.hpp): GasSolver::faceRate()'s
// arithmetic in loops the compiler vectorises. Compiled once per kernel variant (core/Isa.hpp).
#include <algorithm>
#include <cstddef>

#include "cfddem/gas/FaceRates.hpp"

namespace rcfd::gas::RCFD_ISA_NAMESPACE {

void faceRows(const FaceRowInputs& in, int d, int j, int k, int i0, int i1, double* out) {
  constexpr int kChunk = 64;
  const double* const hv = in.spacing;
  const double nu = in.nu, rho = in.rho;
  const auto& n = in.cells;
  const auto& sd = in.faceShape[d];
  const std::ptrdiff_t dStride[3] = {1, sd[0], std::ptrdiff_t(sd[0]) * sd[1]};
  const std::ptrdiff_t cellStride[3] = {1, n[0], std::ptrdiff_t(n[0]) * n[1]};
  const double* const ud = in.u[d];
  const char* const kinds = in.kinds[d];
  const char interior = in.interior;
  const int idx[3] = {0, j, k};
  const double gravity = in.gravity[d], jet = d == 1 ? in.jet : 0.0;
  for (int c0 = i0; c0 < i1; c0 += kChunk) {
    const int m = std::min(kChunk, i1 - c0);
    const std::ptrdiff_t f0 = k * dStride[2] + j * dStride[1] + c0;
    alignas(64) double r[kChunk];
    for (int q = 0; q < m; ++q) r[q] = 0.0;
    for (int e = 0; e < 3; ++e) {
      alignas(64) double a[kChunk];
      if (e == d) {
        for (int q = 0; q < m; ++q) a[q] = ud[f0 + q];
      } else {
        const double* const ue = in.u[e];
        const auto& se = in.faceShape[e];
        const std::ptrdiff_t stride[3] = {1, se[0], std::ptrdiff_t(se[0]) * se[1]};
        const double* const p0 = ue + (k * stride[2] + j * stride[1] + c0);
        const double* const p1 = p0 + stride[e];
        const double* const p2 = p0 - stride[d];
        const double* const p3 = p2 + stride[e];
#pragma omp simd
        for (int q = 0; q < m; ++q) a[q] = 0.25 * (p0[q] + p1[q] + p2[q] + p3[q]);
      }
      // Inside along x (e = 0) the table gives shifts -2..2 and sign 1; along y and z the row's index
      // is fixed, so one table entry serves the whole row.
      const GhostPoint* g = in.ghost[d][e] + std::size_t(e == 0 ? 2 : idx[e]) * 5;
      const double* v0 = ud + f0 + g[0].shift * dStride[e];
      const double* v1 = ud + f0 + g[1].shift * dStride[e];
      const double* v2 = ud + f0 + g[2].shift * dStride[e];
      const double* v3 = ud + f0 + g[3].shift * dStride[e];
      const double* v4 = ud + f0 + g[4].shift * dStride[e];
      const double s0 = g[0].sign, s1 = g[1].sign, s2 = g[2].sign, s3 = g[3].sign, s4 = g[4].sign;
      const double spacing = hv[e];
#pragma omp simd
      for (int q = 0; q < m; ++q)
        r[q] = addAdvectionDiffusion(r[q], a[q], s0 * v0[q], s1 * v1[q], s2 * v2[q], s3 * v3[q], s4 * v4[q], spacing, nu);
    }
    const std::ptrdiff_t ch0 = (std::ptrdiff_t(k) * n[1] + j) * n[0] + c0, cl0 = ch0 - cellStride[d];
    const double* const fx = in.fExplicit;
    const double* const alphaNext = in.alphaNext;
    const double* const source = in.source;
#pragma omp simd
    for (int q = 0; q < m; ++q) {
      const std::ptrdiff_t ch = ch0 + q, cl = cl0 + q;
      const double aF = 0.5 * (alphaNext[cl] + alphaNext[ch]);
      const double fe = 0.5 * (fx[3 * cl + d] + fx[3 * ch + d]);
      const double sF = 0.5 * (source[cl] + source[ch]);
      const double rate = addSources(r[q], gravity, fe, sF, jet, ud[f0 + q], aF, rho);
      out[f0 + q] = kinds[f0 + q] == interior ? rate : 0.0;
    }
  }
}

}  // namespace rcfd::gas::RCFD_ISA_NAMESPACE
