// The step fields (tracers/StepField.hpp): a field built ahead, beside the previous step's motion, is
// taken only for the frames it was built from, and then equals the field built on demand bit for bit.
#include <gtest/gtest.h>

#include <cstring>

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
