// GasSolver: the stable time step, the flow factor and checkpoints (GasSolver.hpp).

#include <limits>
#include <string>

#include "cfddem/gas/GasSolver.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "core/Vec3Packing.hpp"

namespace rcfd::gas {

double GasSolver::stableTimeStep() const { return chooseDt(std::numeric_limits<double>::infinity()); }

void GasSolver::setFlowFactor(double factor) {
  if (!(factor >= 0.0 && factor <= 1.0))
    throw RunError("gas solver: flow factor " + std::to_string(factor) + " is outside [0, 1]");
  flowFactor_ = factor;
  inletVelocity_ = factor * inletVelocity0_;
  nozzleJetVelocity_ = factor * nozzleJetVelocity0_;
  for (std::size_t c = 0; c < source_.size(); ++c) source_[c] = factor * source0_[c];
}


void GasSolver::saveState(h5::File& file, const std::string& group) const {
  file.createGroup(group);
  for (int d = 0; d < 3; ++d) file.write(group + "/u" + std::to_string(d), u_[std::size_t(d)]);
  file.write(group + "/p", p_);
  file.write(group + "/q", std::vector<double>(q_.data(), q_.data() + q_.size()));
  file.write(group + "/alpha", alpha_);
  file.write(group + "/alpha_next", alphaNext_);
  file.write(group + "/dalpha_dt", dAlphaDt_);
  file.write(group + "/beta", beta_);
  file.write(group + "/u_particle", flattenVec3(uParticle_));
  file.write(group + "/f_explicit", flattenVec3(fExplicit_));
  file.setAttribute(group, "time", time_);
  file.setAttribute(group, "last_dt", lastDt_);
  file.setAttribute(group, "flow_factor", flowFactor_);
  file.setAttribute(group, "given_rate", std::int64_t(givenRate_ ? 1 : 0));
}

void GasSolver::loadState(const h5::File& file, const std::string& group) {
  auto readSized = [&](const std::string& name, std::size_t n) {
    std::vector<double> v = file.readDoubles(group + "/" + name);
    if (v.size() != n)
      throw RunError("gas checkpoint " + file.path() + ":" + group + "/" + name + " has " +
                     std::to_string(v.size()) + " values, this grid needs " + std::to_string(n));
    return v;
  };
  const std::size_t cells = alpha_.size();
  for (int d = 0; d < 3; ++d) u_[std::size_t(d)] = readSized("u" + std::to_string(d), u_[std::size_t(d)].size());
  p_ = readSized("p", cells);
  updatePressureGradient();
  const std::vector<double> q = readSized("q", std::size_t(q_.size()));
  q_ = Eigen::Map<const Eigen::VectorXd>(q.data(), Eigen::Index(q.size()));
  alpha_ = readSized("alpha", cells);
  alphaNext_ = readSized("alpha_next", cells);
  dAlphaDt_ = readSized("dalpha_dt", cells);
  beta_ = readSized("beta", cells);
  uParticle_ = unflattenVec3(readSized("u_particle", 3 * cells));
  fExplicit_ = unflattenVec3(readSized("f_explicit", 3 * cells));
  time_ = file.doubleAttribute(group, "time");
  lastDt_ = file.doubleAttribute(group, "last_dt");
  setFlowFactor(file.doubleAttribute(group, "flow_factor"));
  givenRate_ = file.intAttribute(group, "given_rate") != 0;
  hasDrag_ = false;
  for (double b : beta_) hasDrag_ = hasDrag_ || b > 0;
  matrixDirty_ = true;  // the pressure matrix and its preconditioner are rebuilt at the next step
}

}  // namespace rcfd::gas
