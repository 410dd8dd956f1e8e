// The step fields (tracers/StepField.hpp): a field built ahead, beside the previous step's motion, is
// taken only for the frames it was built from, and then equals the field built on demand bit for bit.
#include <algorithm>
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "TracerTestSupport.hpp"
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

TEST(StepFields, AFieldHoldsItsFramesValuesPaddedWithZero) {
  // On a frame (a copy, the vector path) and between two (the blend in double): (x, y, z, 0) per cell.
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
        const float copied = d < 3 ? a[i] : 0.0f;
        const float blended = d < 3 ? float(double(a[i]) + 0.25 * (double(b[i]) - double(a[i]))) : 0.0f;
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
