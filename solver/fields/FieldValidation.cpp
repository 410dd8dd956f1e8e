#include "fields/FieldValidation.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <cstdint>
#include <cstring>
#include <sstream>

namespace rcfd {

namespace {
std::string str(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
  std::ostringstream out;
  out.precision(9);
  out << v;
  return out.str();
}

// First non-finite entry of `values` (flat index), or -1. The scan tests the exponent bits (all ones:
// NaN or Inf) without an early exit so it vectorises; only a bad frame pays for the search.
std::int64_t firstNonFinite(const std::vector<float>& values) {
  std::uint32_t bad = 0;
  const float* v = values.data();
  const std::size_t n = values.size();
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t bits;
    std::memcpy(&bits, v + i, sizeof bits);
    bad |= std::uint32_t((bits & 0x7f800000u) == 0x7f800000u);
  }
  if (!bad) return -1;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return std::int64_t(i);
  }
  return -1;
}
}  // namespace

void validateGrid(const CartesianGrid& grid, std::vector<Violation>& violations) {
  const char* axis[3] = {"x", "y", "z"};
  for (int d = 0; d < 3; ++d) {
    if (!std::isfinite(grid.origin[d])) {
      violations.push_back({"/grid@origin", std::string(axis[d]) + " is " + str(grid.origin[d]) +
                                                "; it must be a finite number [m]"});
    }
    if (!(std::isfinite(grid.spacing[d]) && grid.spacing[d] > 0.0)) {
      violations.push_back({"/grid@spacing", std::string(axis[d]) + " is " + str(grid.spacing[d]) +
                                                 "; it must be finite and > 0 [m]"});
    }
    if (grid.shape[d] < 1) {
      violations.push_back({"/grid@shape", std::string("n") + axis[d] + " is " +
                                               std::to_string(grid.shape[d]) + "; it must be >= 1"});
    }
  }
}

void validateFluidFraction(const std::vector<float>& fluidFraction, const CartesianGrid& grid,
                           std::vector<Violation>& violations) {
  if (std::int64_t(fluidFraction.size()) != grid.cellCount()) {
    violations.push_back({"/grid/fluid_fraction", "has " + std::to_string(fluidFraction.size()) +
                                                      " values; the grid has " +
                                                      std::to_string(grid.cellCount()) + " cells"});
    return;
  }
  for (std::size_t c = 0; c < fluidFraction.size(); ++c) {
    const float f = fluidFraction[c];
    if (!(f >= 0.0f && f <= 1.0f)) {  // also catches NaN
      const auto ijk = grid.cellIjk(std::int64_t(c));
      violations.push_back({"/grid/fluid_fraction",
                            "cell (" + std::to_string(ijk[0]) + ", " + std::to_string(ijk[1]) + ", " +
                                std::to_string(ijk[2]) + ") is " + str(f) +
                                "; the open volume fraction must be in [0, 1]"});
      return;  // one example is enough; a broken field usually breaks many cells
    }
  }
}

void validateDtRec(double dtRec, std::vector<Violation>& violations) {
  if (!(std::isfinite(dtRec) && dtRec > 0.0)) {
    violations.push_back({"/@dt_rec", "is " + str(dtRec) + "; the sampling interval must be finite and > 0 [s]"});
  }
}

void checkFrame(const FieldFrame& frame, int index, const CartesianGrid& grid, const std::string& source) {
  const std::int64_t cells = grid.cellCount();
  std::vector<Violation> violations;
  struct Part {
    const char* name;
    const std::vector<float>* values;
    int components;
  };
  std::vector<Part> parts = {{"/frames/alpha_p", &frame.alpha_p, 1},
                             {"/frames/u_p", &frame.u_p, 3},
                             {"/frames/u_g", &frame.u_g, 3}};
  // The velocity spread: all of it or none.
  const bool spread = std::any_of(std::begin(kVelocitySpreadFields), std::end(kVelocitySpreadFields),
                                  [&](const OptionalFrameField& f) { return !(frame.*f.member).empty(); });
  if (spread) {
    for (const auto& f : kVelocitySpreadFields) parts.push_back({f.path, &(frame.*f.member), f.components});
  }
  for (const auto& p : parts) {
    if (std::int64_t(p.values->size()) != cells * p.components) {
      violations.push_back({p.name, "frame " + std::to_string(index) + " has " +
                                        std::to_string(p.values->size()) + " values; expected " +
                                        std::to_string(cells * p.components) + " (" +
                                        std::to_string(cells) + " cells x " +
                                        std::to_string(p.components) + ")"});
      continue;
    }
    const std::int64_t bad = firstNonFinite(*p.values);
    if (bad >= 0) {
      const auto ijk = grid.cellIjk(bad / p.components);
      violations.push_back({p.name, "frame " + std::to_string(index) + ", cell (" +
                                        std::to_string(ijk[0]) + ", " + std::to_string(ijk[1]) + ", " +
                                        std::to_string(ijk[2]) + ") holds " +
                                        str((*p.values)[std::size_t(bad)]) +
                                        "; every value must be finite"});
    }
  }
  if (violations.empty()) {
    // alpha_P is a volume fraction: in [0, 1]. A branch-free scan (it vectorises); only a bad frame pays
    // for the search of the cell.
    const std::vector<float>& alpha = frame.alpha_p;
    float lo = 0.0f, hi = 1.0f;
    for (const float a : alpha) lo = std::min(lo, a), hi = std::max(hi, a);
    if (lo < 0.0f || hi > 1.0f) {
      for (std::size_t c = 0; c < alpha.size(); ++c) {
        if (alpha[c] >= 0.0f && alpha[c] <= 1.0f) continue;
        const auto ijk = grid.cellIjk(std::int64_t(c));
        violations.push_back({"/frames/alpha_p", "frame " + std::to_string(index) + ", cell (" + std::to_string(ijk[0]) +
                                                     ", " + std::to_string(ijk[1]) + ", " + std::to_string(ijk[2]) +
                                                     ") holds " + str(alpha[c]) +
                                                     "; a volume fraction must be in [0, 1]"});
        break;
      }
    }
  }
  if (spread && violations.empty()) {
    // Shares in [0, 1] and variances >= 0, within float rounding of the writer's arithmetic.
    auto firstOutside = [](const std::vector<float>& values, float lo, float hi) -> std::int64_t {
      for (std::size_t i = 0; i < values.size(); ++i) {
        if (!(values[i] >= lo && values[i] <= hi)) return std::int64_t(i);
      }
      return -1;
    };
    const float inf = std::numeric_limits<float>::infinity();
    const struct {
      const char* name;
      const std::vector<float>* values;
      int components;
      float lo, hi;
      const char* rule;
    } ranges[2] = {{"/frames/up_fraction", &frame.up_fraction, 1, 0.0f, 1.0f, "must be in [0, 1]"},
                   {"/frames/u_p_variance", &frame.u_p_variance, 3, 0.0f, inf, "must be >= 0"}};
    for (const auto& r : ranges) {
      const std::int64_t bad = firstOutside(*r.values, r.lo, r.hi);
      if (bad < 0) continue;
      const auto ijk = grid.cellIjk(bad / r.components);
      violations.push_back({r.name, "frame " + std::to_string(index) + ", cell (" + std::to_string(ijk[0]) + ", " +
                                        std::to_string(ijk[1]) + ", " + std::to_string(ijk[2]) + ") holds " +
                                        str((*r.values)[std::size_t(bad)]) + "; it " + r.rule});
    }
  }
  if (!violations.empty()) throw InputError(source, std::move(violations));
}

}  // namespace rcfd
