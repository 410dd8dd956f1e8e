#include "cfddem/RollingFrictionCdt.hpp"

namespace rcfd {
namespace {
const bool registered = RollingModelRegistry::add(
    "cdt", "constant directional torque mu_r k_n delta R* against the relative rolling (Ai et al. 2011)",
    [](const DemMaterial&) { return std::make_unique<RollingFrictionCdt>(); });
}  // namespace
}  // namespace rcfd
