// The Beetstra drag law, registered as "beetstra" (DragModel.hpp).

#include <cmath>

#include "cfddem/coupling/DragModel.hpp"

namespace rcfd::coupling {

double beetstraDrag(double eps, double re) {
  const double phi = 1.0 - eps;
  const double viscous = 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * std::sqrt(std::max(phi, 0.0)));
  if (!(re > 0.0)) return viscous;  // the inertial term vanishes like Re^(1.157 + 2 phi)
  const double inertial = 0.413 * re / (24.0 * eps * eps) * (1.0 / eps + 3.0 * eps * phi + 8.4 * std::pow(re, -0.343)) /
                          (1.0 + std::pow(10.0, 3.0 * phi) * std::pow(re, -0.5 * (1.0 + 4.0 * phi)));
  return viscous + inertial;
}

namespace {

class BeetstraDrag final : public DragModel {
 public:
  std::string name() const override { return "beetstra"; }
  double normalisedDrag(double eps, double re) const override { return beetstraDrag(eps, re); }
};

const bool registered = DragModelRegistry::add(
    "beetstra", "Beetstra, van der Hoef & Kuipers (2007) drag F(eps, Re), Re on the primary diameter",
    [](const Scene&) { return std::make_unique<BeetstraDrag>(); });

}  // namespace
}  // namespace rcfd::coupling
