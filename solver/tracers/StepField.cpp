#include "tracers/StepField.hpp"

#if defined(__AVX__)
#include <immintrin.h>
#endif

namespace rcfd {

void StepVelocityField::build(const FrameSampler& sampler, bool useGas, bool parallel, StepFieldLayout layout,
                              float massWeight) {
  const auto& fa = useGas ? sampler.frame().u_g : sampler.frame().u_p;
  const FieldFrame* next = sampler.nextFrame();
  frameValues_ = nullptr;
  weighted_ = false;
  // A mass-weighted u_P has no frame array to refer to: it is built padded whatever the layout asked.
  if (massWeight > 0.0f && !useGas) {
    buildWeighted(sampler, parallel, massWeight);
    return;
  }
  if (!next && layout == StepFieldLayout::Any) {
    frameValues_ = fa.data();
    return;
  }
  const float* fb = next ? (useGas ? next->u_g : next->u_p).data() : nullptr;
  const double w = sampler.blend();
  const std::int64_t cells = std::int64_t(fa.size() / 3);
  data_.resize(std::size_t(cells));
  const float* const a = fa.data();
  float* const out = data_.empty() ? nullptr : data_[0].data();
  if (fb) {
#pragma omp parallel for schedule(static) if (parallel)
    for (std::int64_t c = 0; c < cells; ++c) {
      for (int d = 0; d < 3; ++d) {
        out[4 * c + d] = float(double(a[3 * c + d]) + w * (double(fb[3 * c + d]) - double(a[3 * c + d])));
      }
      out[4 * c + 3] = 1.0f;
    }
    return;
  }
  // A step on a frame itself (every step when the database is sampled at the step): a copy, one
  // masked 16-byte load, (a blend) and one store per cell; GCC's own loop moves a float at a time.
#pragma omp parallel for schedule(static) if (parallel)
  for (std::int64_t c = 0; c < cells; ++c) {
#if defined(__AVX512F__) && defined(__AVX512VL__)
    _mm_store_ps(out + 4 * c, _mm_mask_loadu_ps(_mm_set1_ps(1.0f), 0x7, a + 3 * c));  // (x, y, z, 1), no read past z
#elif defined(__AVX__)
    const __m128 xyz = _mm_maskload_ps(a + 3 * c, _mm_setr_epi32(-1, -1, -1, 0));  // no read past z
    _mm_store_ps(out + 4 * c, _mm_blend_ps(xyz, _mm_set1_ps(1.0f), 0x8));
#else
    for (int d = 0; d < 3; ++d) out[4 * c + d] = a[3 * c + d];
    out[4 * c + 3] = 1.0f;
#endif
  }
}

void StepVelocityField::buildWeighted(const FrameSampler& sampler, bool parallel, float massWeight) {
  const FieldFrame& fa = sampler.frame();
  const FieldFrame* fb = sampler.nextFrame();
  const double w = sampler.blend();
  const std::int64_t cells = std::int64_t(fa.alpha_p.size());
  data_.resize(std::size_t(cells));
  float* const out = data_.empty() ? nullptr : data_[0].data();
#pragma omp parallel for schedule(static) if (parallel)
  for (std::int64_t c = 0; c < cells; ++c) {
    const double wa = double(fa.alpha_p[std::size_t(c)]) + massWeight;
    const double wb = fb ? double(fb->alpha_p[std::size_t(c)]) + massWeight : wa;
    for (int d = 0; d < 3; ++d) {
      const double ma = wa * fa.u_p[std::size_t(3 * c + d)];
      const double mb = fb ? wb * fb->u_p[std::size_t(3 * c + d)] : ma;
      out[4 * c + d] = float(ma + w * (mb - ma));
    }
    out[4 * c + 3] = float(wa + w * (wb - wa));
  }
  weighted_ = true;
}

}  // namespace rcfd
