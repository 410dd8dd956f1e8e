#pragma once
/// \file StepField.hpp
/// A recurrence velocity field prepared for one tracer step: 4 floats per cell (x, y, z, 0), 16-byte
/// aligned, blended between the step's two frames once per cell rather than once per tracer and
/// corner. The motion kernel then fetches a corner and its x-neighbour with one 32-byte load.
/// Rebuilding costs one pass over the cells (74k) per step against 8-16 corner loads for each of the
/// 473k tracers. Stages that sample a few points (spray parcels, deposition) take, on a frame, the
/// frame's own 3 floats per cell instead (StepFieldLayout::Any). Blended values are rounded to float,
/// the precision the database stores frames in.

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "tracers/BlockSampling.hpp"
#include "tracers/FrameSampler.hpp"

namespace rcfd {

/// How a stage reads a step field: with the block path's corner-pair loads (Padded: 4 floats per cell),
/// or at a few points only (Any: on a frame, the frame's own array of 3 floats per cell does, and
/// costs no copy).
enum class StepFieldLayout { Padded, Any };

class StepVelocityField {
 public:
  /// Fills the field from the sampler's frame(s): u_P^rec, or u_G^rec when useGas. With layout Any, a
  /// step on a frame refers to the frame's array, which must outlive the field's use (the step's frames
  /// are held for the step: TracerContext, StepFields).
  void build(const FrameSampler& sampler, bool useGas, bool parallel,
             StepFieldLayout layout = StepFieldLayout::Padded, float massWeight = 0.0f);

  /// The field as stride() floats per cell: (x, y, z, 1), (w u, w) when weighted(), or (x, y, z) on a
  /// frame's own array.
  const float* floats() const { return frameValues_ ? frameValues_ : (data_.empty() ? nullptr : data_[0].data()); }
  int stride() const { return frameValues_ ? 3 : 4; }
  bool padded() const { return !frameValues_; }
  bool weighted() const { return weighted_; }

 private:
  /// (w u_P, w) per cell with w = alpha_P^rec + massWeight, each blended between the frames: a sample
  /// between cell centres is then the particle flux over the particle volume there (the cells'
  /// alpha_P u_P and alpha_P interpolated alike), a cell centre's is its own u_P.
  void buildWeighted(const FrameSampler& sampler, bool parallel, float massWeight);

  bool weighted_ = false;
  const float* frameValues_ = nullptr;  ///< the frame's own u (layout Any, on a frame), else null
  std::vector<Eigen::Array4f> data_;
};

/// The step's u_P^rec and u_G^rec as step fields, each built on its first use in a step and then shared
/// by every stage that reads it (the motion kernel, the spray parcels, deposition): a field no stage
/// reads is never built, and none is built twice. TracerSimulation invalidates them when the step's
/// frames change.
class StepFields {
 public:
  void invalidate() { built_[0] = built_[1] = false; }
  /// u_P^rec mass-weighted with weight alpha_P^rec + `epsilon` (StepVelocityField::buildWeighted());
  /// 0: plain trilinear velocity.
  void setMassWeight(float epsilon) { massWeight_ = epsilon; invalidate(); }
  /// u_P^rec (useGas false) or u_G^rec of the sampler's frames: the one built ahead for these frames,
  /// if any, else built now.
  /// With layout Any, a field already built padded this step is returned as it is; a padded request
  /// after an Any one rebuilds the field in place.
  const StepVelocityField& velocity(const FrameSampler& sampler, bool useGas, bool parallel,
                                    StepFieldLayout layout = StepFieldLayout::Padded) {
    const int k = useGas ? 1 : 0;
    if (!built_[k] || (layout == StepFieldLayout::Padded && !fields_[k].padded())) {
      Ahead& a = ahead_[k];
      if (a.frame && a.frame.get() == &sampler.frame() && a.next.get() == sampler.nextFrame() &&
          a.blend == sampler.blend()) {
        std::swap(fields_[k], a.field);  // the same build(), done earlier
      } else {
        fields_[k].build(sampler, useGas, parallel, layout, massWeight_);
      }
      a.frame.reset(), a.next.reset();
      built_[k] = true;
    }
    return fields_[k];
  }
  /// Builds the field of a later step's frames now, on the calling thread (beside the motion of the
  /// current step, which reads only the current fields); velocity() takes it when that step comes
  /// with the same frames. Holds the frames until then.
  void buildAhead(const CartesianGrid& grid, std::shared_ptr<const FieldFrame> frame,
                  std::shared_ptr<const FieldFrame> next, double blend, bool useGas) {
    Ahead& a = ahead_[useGas ? 1 : 0];
    const FrameSampler sampler(grid, frame.get(), next.get(), blend);
    a.field.build(sampler, useGas, false, StepFieldLayout::Padded, massWeight_);
    a.frame = std::move(frame);
    a.next = sampler.nextFrame() ? std::move(next) : nullptr;
    a.blend = sampler.blend();
  }

 private:
  struct Ahead {
    std::shared_ptr<const FieldFrame> frame, next;  ///< the frames `field` was built from (null: none)
    double blend = 0.0;
    StepVelocityField field;
  };
  StepVelocityField fields_[2];
  bool built_[2] = {false, false};
  float massWeight_ = 0.0f;
  Ahead ahead_[2];
};

/// u at single points of a step field, with the motion kernel's block arithmetic
/// (block::interpolateCorners, float) for one point: the motion kernel's scalar path and the spray
/// parcels sample with it.
class StepFieldSampler {
 public:
  StepFieldSampler(const StepVelocityField& field, const TrilinearLocator& locator)
      : values_(field.floats()), stride_(field.stride()), locator_(locator), grid_(locator.constants()) {
    corners_.set(locator.offsets32(), stride_);
    corners_.weighted = field.weighted();
  }
  /// Grid coordinates of p in float (block::gridCoordinate()): where the motion kernel's u_P^rec
  /// samples and midpoints are taken.
  Eigen::Vector3f gridCoordinates(const Eigen::Vector3d& p) const {
    return {block::gridCoordinate(p.x(), grid_.ox, grid_.ix), block::gridCoordinate(p.y(), grid_.oy, grid_.iy),
            block::gridCoordinate(p.z(), grid_.oz, grid_.iz)};
  }
  /// u at grid coordinates g, in float: the arithmetic of block::locateGridBlock() and sampleBlock3().
  Eigen::Vector3f sampleAtGrid(const Eigen::Vector3f& g) const {
    float f[3];
    const std::int32_t base = grid_.locate(g.x(), g.y(), g.z(), f[0], f[1], f[2]);
    Eigen::Vector3f u;
    interpolate(values_ + stride_ * std::int64_t(base), f[0], f[1], f[2], u.data());
    return u;
  }
  /// The inverse grid spacing in float, per axis (midpoints in grid coordinates).
  Eigen::Vector3f inverseSpacing() const { return {grid_.fix, grid_.fiy, grid_.fiz}; }

  Eigen::Vector3d sample(const Eigen::Vector3d& p) const {
    const TrilinearStencil s = locator_.locate(p);
    float u[3];
    interpolate(values_ + stride_ * s.base, float(s.f[0]), float(s.f[1]), float(s.f[2]), u);
    return {double(u[0]), double(u[1]), double(u[2])};
  }

 private:
  void interpolate(const float* at, float fx, float fy, float fz, float u[3]) const {
    if (corners_.weighted) {
      block::interpolateWeightedCorners(at, corners_.off, fx, fy, fz, u);
    } else {
      block::interpolateCorners(at, corners_.off, fx, fy, fz, u);
    }
  }

  const float* values_;  ///< the field's floats, taken when constructed
  int stride_;
  const TrilinearLocator& locator_;
  block::GridConstants grid_;
  block::CornerOffsets corners_;
};

}  // namespace rcfd
