// The step fields (tracers/StepField.hpp): a field built ahead, beside the previous step's motion, is
// taken only for the frames it was built from, and then equals the field built on demand bit for bit.
#include <algorithm>
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "TracerTestSupport.hpp"
#include "tracers/FrameInterpolation.hpp"
#include "tracers/StepField.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

struct ThreeFrames {
  Scene scene = boxScene({0.1, 0.1, 0.05}, 0.01, 10, 0.005, {"transport"});
  CartesianGrid grid = gridOf(scene);
  std::shared_ptr<FieldDatabase> db;
  ThreeFrames() {
    // Every cell, component and frame its own value (a swapped frame or blend would show).
    db = database(scene, 3, 0.005, [](int n, double, FieldFrame& f) {
      std::fill(f.alpha_p.begin(), f.alpha_p.end(), 0.3f);  // particles everywhere: u_P as given
      for (std::size_t i = 0; i < f.u_p.size(); ++i) {
        f.u_p[i] = float(0.01 * double(i) + n);
        f.u_g[i] = float(-0.02 * double(i) + 3.0 * n);
      }
    });
  }
  /// A field built on demand, the reference.
  StepVelocityField built(int frame, int next, double blend, bool useGas) const {
    const auto a = db->frame(frame), b = db->frame(next);
    StepVelocityField f;
    f.build(FrameSampler(grid, a.get(), b.get(), blend), useGas, false);
    return f;
  }
  bool equal(const StepVelocityField& x, const StepVelocityField& y) const {
    return std::memcmp(x.floats(), y.floats(), sizeof(float) * 4 * std::size_t(grid.cellCount())) == 0;
  }
};

TEST(StepFields, BuiltAheadEqualsBuiltOnDemandForTheSameFrames) {
  const ThreeFrames t;
  for (const bool useGas : {false, true}) {
    StepFields fields;
    const auto f1 = t.db->frame(1), f2 = t.db->frame(2);
    fields.buildAhead(t.grid, f1, f2, 0.25, useGas);
    const StepVelocityField& got = fields.velocity(FrameSampler(t.grid, f1.get(), f2.get(), 0.25), useGas, false);
    EXPECT_TRUE(t.equal(got, t.built(1, 2, 0.25, useGas))) << "useGas " << useGas;
    EXPECT_FALSE(t.equal(got, t.built(1, 2, 0.5, useGas)));  // the comparison can fail
  }
}

TEST(StepFields, AFieldBuiltAheadForOtherFramesIsNotTaken) {
  const ThreeFrames t;
  StepFields fields;
  const auto f0 = t.db->frame(0), f1 = t.db->frame(1), f2 = t.db->frame(2);
  // Ahead for frame 1 blended toward 2; the step comes with frame 0 alone, then with another blend.
  fields.buildAhead(t.grid, f1, f2, 0.5, false);
  EXPECT_TRUE(t.equal(fields.velocity(FrameSampler(t.grid, f0.get()), false, false), t.built(0, 0, 0.0, false)));
  fields.invalidate();
  fields.buildAhead(t.grid, f1, f2, 0.5, false);
  EXPECT_TRUE(t.equal(fields.velocity(FrameSampler(t.grid, f1.get(), f2.get(), 0.75), false, false),
                      t.built(1, 2, 0.75, false)));
  // u_G is not taken from a u_P field built ahead.
  fields.invalidate();
  fields.buildAhead(t.grid, f1, nullptr, 0.0, false);
  EXPECT_TRUE(t.equal(fields.velocity(FrameSampler(t.grid, f1.get()), true, false), t.built(1, 1, 0.0, true)));
  // The u_P field built ahead for frame 1 is still taken by a step of frame 1.
  EXPECT_TRUE(t.equal(fields.velocity(FrameSampler(t.grid, f1.get()), false, false), t.built(1, 1, 0.0, false)));
}

}  // namespace

TEST(StepFields, AFieldHoldsItsFramesValuesPaddedWithOne) {
  // On a frame (a copy, the vector path) and between two (the blend in double): (x, y, z, 1) per cell,
  // the weight 1 of a field that is not mass-weighted.
  const ThreeFrames t;
  const auto f1 = t.db->frame(1), f2 = t.db->frame(2);
  for (const bool useGas : {false, true}) {
    const auto& a = useGas ? f1->u_g : f1->u_p;
    const auto& b = useGas ? f2->u_g : f2->u_p;
    const StepVelocityField onFrame = t.built(1, 1, 0.0, useGas);
    const StepVelocityField between = t.built(1, 2, 0.25, useGas);
    std::size_t wrong = 0;
    for (std::int64_t c = 0; c < t.grid.cellCount(); ++c) {
      for (int d = 0; d < 4; ++d) {
        const std::size_t i = 3 * std::size_t(c) + std::size_t(d);
        const float copied = d < 3 ? a[i] : 1.0f;
        const float blended = d < 3 ? float(double(a[i]) + 0.25 * (double(b[i]) - double(a[i]))) : 1.0f;
        wrong += onFrame.floats()[4 * c + d] != copied;
        wrong += between.floats()[4 * c + d] != blended;
      }
    }
    EXPECT_EQ(wrong, 0u) << "useGas " << useGas;
  }
}

TEST(StepFields, LayoutAnyOnAFrameIsTheFrameItselfAndSamplesAlike) {
  // Stages sampling a few points take a step on a frame as the frame's own 3 floats per cell; their
  // samples (single points and blocks) equal the padded field's bit for bit.
  const ThreeFrames t;
  const auto f1 = t.db->frame(1), f2 = t.db->frame(2);
  const FrameSampler onFrame(t.grid, f1.get());
  StepFields fields;
  const StepVelocityField& view = fields.velocity(onFrame, true, false, StepFieldLayout::Any);
  EXPECT_EQ(view.floats(), f1->u_g.data());
  EXPECT_EQ(view.stride(), 3);
  const StepVelocityField padded = t.built(1, 1, 0.0, true);
  ASSERT_EQ(padded.stride(), 4);
  const TrilinearLocator& locator = onFrame.locator();
  const StepFieldSampler a(view, locator), b(padded, locator);
  constexpr int n = block::kBlock;
  alignas(64) double x[n], y[n], z[n], ux[2][n], uy[2][n], uz[2][n];
  alignas(64) static constexpr double kZero[n] = {};
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> px(-0.01, 0.11), py(-0.01, 0.11), pz(-0.01, 0.06);  // some outside
  for (int k = 0; k < n; ++k) x[k] = px(gen), y[k] = py(gen), z[k] = pz(gen);
  block::BlockStencils s;
  block::locateBlock(locator.constants(), n, x, y, z, s);
  int r = 0;
  for (const StepVelocityField* f : {&view, &padded}) {
    block::CornerOffsets corners;
    corners.set(locator.offsets32(), f->stride());
    block::sampleBlock(f->floats(), corners, s, n, kZero, kZero, kZero, ux[r], uy[r], uz[r]);
    ++r;
  }
  int differ = 0, moving = 0;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d p(x[k], y[k], z[k]);
    differ += a.sample(p) != b.sample(p);
    differ += ux[0][k] != ux[1][k] || uy[0][k] != uy[1][k] || uz[0][k] != uz[1][k];
    differ += a.sample(p) != Eigen::Vector3d(ux[1][k], uy[1][k], uz[1][k]);
    moving += ux[1][k] != 0.0;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(moving, n / 2);  // the comparison sees values
  // A padded request in the same step rebuilds it in place; a blend is always padded.
  EXPECT_EQ(fields.velocity(onFrame, true, false).stride(), 4);
  EXPECT_TRUE(t.equal(fields.velocity(onFrame, true, false), padded));
  EXPECT_EQ(fields.velocity(onFrame, true, false, StepFieldLayout::Any).stride(), 4);  // already padded: kept
  fields.invalidate();
  const StepVelocityField& between =
      fields.velocity(FrameSampler(t.grid, f1.get(), f2.get(), 0.25), true, false, StepFieldLayout::Any);
  EXPECT_EQ(between.stride(), 4);
  EXPECT_TRUE(t.equal(between, t.built(1, 2, 0.25, true)));
}

// The mass-weighted u_P field holds (w u_P, w), w = alpha_P + kMassWeightFloor, each blended between the
// frames; sampled at a cell centre it gives the cell's u_P, halfway between two cells the flux-weighted
// mean (w1 u1 + w2 u2) / (w1 + w2), and on a uniform alpha_P the trilinear velocity. u_G is never weighted.
TEST(StepFields, TheMassWeightedFieldSamplesTheParticleFlux) {
  Scene scene = boxScene({0.1, 0.1, 0.05}, 0.01, 10, 0.005, {"transport"});
  const CartesianGrid grid = gridOf(scene);
  auto db = database(scene, 3, 0.005, [&grid](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      f.alpha_p[std::size_t(c)] = ijk[0] % 2 == 0 ? 0.5f : (n == 2 ? 0.1f : 0.02f);  // dense and dilute columns
      f.u_p[3 * std::size_t(c) + 1] = ijk[0] % 2 == 0 ? -0.25f : 2.0f + float(n);
      f.u_g[3 * std::size_t(c)] = 1.5f;
    }
  });
  const auto f1 = db->frame(1), f2 = db->frame(2);
  const TrilinearLocator locator(grid);
  StepFields fields;
  fields.setMassWeight(kMassWeightFloor);
  const FrameSampler onFrame(grid, f1.get());
  const StepVelocityField& u = fields.velocity(onFrame, false, false);
  ASSERT_TRUE(u.weighted());
  const StepFieldSampler sample(u, locator);
  const Eigen::Vector3d dense = grid.cellCenter(4, 5, 2), dilute = grid.cellCenter(5, 5, 2);
  EXPECT_NEAR(sample.sample(dense).y(), -0.25, 1e-6);
  EXPECT_NEAR(sample.sample(dilute).y(), 3.0, 1e-6);
  const double w1 = 0.5 + kMassWeightFloor, w2 = 0.02 + kMassWeightFloor;
  EXPECT_NEAR(sample.sample(0.5 * (dense + dilute)).y(), (w1 * -0.25 + w2 * 3.0) / (w1 + w2), 1e-6);
  // Between frames 1 and 2 the weights and momenta blend: a quarter of the way to frame 2.
  fields.invalidate();
  const FrameSampler between(grid, f1.get(), f2.get(), 0.25);
  const StepFieldSampler blended(fields.velocity(between, false, false), locator);
  const double b2 = w2 + 0.25 * (0.1 - 0.02), m2 = w2 * 3.0 + 0.25 * ((0.1 + kMassWeightFloor) * 4.0 - w2 * 3.0);
  EXPECT_NEAR(blended.sample(0.5 * (dense + dilute)).y(), (w1 * -0.25 + m2) / (w1 + b2), 1e-5);
  // u_G: not weighted, weight 1 read as such.
  const StepVelocityField& gas = fields.velocity(between, true, false);
  EXPECT_FALSE(gas.weighted());
  EXPECT_NEAR(StepFieldSampler(gas, locator).sample(0.5 * (dense + dilute)).x(), 1.5, 1e-6);
  // A uniform alpha_P gives the trilinear velocity.
  auto uniform = database(scene, 3, 0.005, [&grid](int, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      f.alpha_p[std::size_t(c)] = 0.3f;
      f.u_p[3 * std::size_t(c) + 1] = float(grid.cellIjk(c)[0]);
    }
  });
  StepFields plainFields, weightedFields;
  weightedFields.setMassWeight(kMassWeightFloor);
  const auto g1 = uniform->frame(1);
  const FrameSampler on(grid, g1.get());
  const StepFieldSampler plain(plainFields.velocity(on, false, false), locator),
      weighted(weightedFields.velocity(on, false, false), locator);
  std::mt19937_64 gen(3);
  std::uniform_real_distribution<double> px(-0.05, 0.05), py(0.0, 0.1), pz(0.0, 0.05);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d p(px(gen), py(gen), pz(gen));
    EXPECT_NEAR(weighted.sample(p).y(), plain.sample(p).y(), 1e-5) << p.transpose();
  }
}
