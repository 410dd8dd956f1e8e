#include "cfddem/HertzMindlin.hpp"
#include "cfddem/DemParallel.hpp"

#include <algorithm>
#include <stdexcept>

namespace rcfd {

using Eigen::Vector3d;

namespace {
const bool registered = ContactModelRegistry::add(
    "hertz_mindlin",
    "Hertz normal + Mindlin tangential spring with history and Coulomb limit, damping from e "
    "(LIGGGHTS hertz/tangential history)",
    [](const DemMaterial& m) { return std::make_unique<HertzMindlin>(m); });
}  // namespace

void HertzMindlin::setRollingModel(const RollingModel* rolling) {
  if (rolling && rolling->name() != "cdt")
    throw std::invalid_argument("hertz_mindlin implements the rolling model \"cdt\", not \"" +
                                rolling->name() + "\"");
  rolling_ = rolling != nullptr;
}

void HertzMindlin::computePairs(ContactContext& ctx) const {
  if (ctx.direct) {
    if (rolling_) pairs<true, true>(ctx);
    else pairs<false, true>(ctx);
  } else {
    if (rolling_) pairs<true, false>(ctx);
    else pairs<false, false>(ctx);
  }
}

void HertzMindlin::computeWalls(ContactContext& ctx, long i, Vector3d& force, Vector3d& torque,
                                double& max_overlap, long& contacts) const {
  if (rolling_) walls<true>(ctx, i, force, torque, max_overlap, contacts);
  else walls<false>(ctx, i, force, torque, max_overlap, contacts);
}

template <bool Rolling, bool Direct>
void HertzMindlin::pairs(ContactContext& ctx) const {
  DemParticles& p = ctx.particles;
  NeighbourList& list = ctx.list;
  PairForces& out = ctx.pair_forces;
  const ContactParams params = material_.particle_particle;
  const long n = static_cast<long>(p.size());
  const double dt = ctx.dt;
  double max_overlap = 0.0;
  long contacts = 0;
#pragma omp parallel for schedule(dynamic, 128) reduction(max : max_overlap) reduction(+ : contacts) if (!Direct && n >= kDemParallelMinParticles)
  for (long i = 0; i < n; ++i) {
    const Vector3d xi = p.x[i], vi = p.v[i], wi = p.omega[i];
    const double ri = p.radius[i], mi = p.mass[i];
    Vector3d fi = Vector3d::Zero(), ti = Vector3d::Zero();
    for (auto q = list.row_start[i]; q < list.row_start[i + 1]; ++q) {
      const auto k = list.j[q];
      const Vector3d d = xi - p.x[k];
      const double rsum = ri + p.radius[k];
      const double r2 = d.squaredNorm();
      if (r2 >= rsum * rsum) {
        list.shear[q].setZero();
        if constexpr (!Direct) out.active[q] = 0;
        continue;
      }
      const double r = std::sqrt(r2);
      const Vector3d nrm = d / r;
      const double delta = rsum - r;
      const double rk = p.radius[k];
      const Vector3d vc = vi - p.v[k] - (ri * wi + rk * p.omega[k]).cross(nrm);
      const double m_eff = mi * p.mass[k] / (mi + p.mass[k]);
      const double r_eff = ri * rk / rsum;
      HertzMindlinContact c;
      hertzMindlinContact<Rolling>(params, delta, nrm, vc, wi - p.omega[k], m_eff, r_eff, dt,
                                   list.shear[q], c);
      if constexpr (Direct) {
        p.force[i] += c.force;
        p.force[k] -= c.force;
        p.torque[i] += -ri * c.n_x_ft + c.roll;
        p.torque[k] += -rk * c.n_x_ft - c.roll;
      } else {
        fi += c.force;
        ti += -ri * c.n_x_ft + c.roll;
        out.active[q] = 1;
        out.force[q] = c.force;
        out.torque_j[q] = -rk * c.n_x_ft - c.roll;
      }
      max_overlap = std::max(max_overlap, delta / std::min(ri, rk));
      ++contacts;
    }
    if constexpr (!Direct) {
      p.force[i] = fi;
      p.torque[i] = ti;
    }
  }
  ctx.max_overlap_fraction = std::max(ctx.max_overlap_fraction, max_overlap);
  ctx.contacts += contacts;
}

template <bool Rolling>
void HertzMindlin::walls(ContactContext& ctx, long i, Vector3d& force, Vector3d& torque,
                         double& max_overlap, long& contacts) const {
  const DemParticles& p = ctx.particles;
  const NeighbourList& list = ctx.list;
  WallHistory& hist = ctx.wall_history;
  const ContactParams& params = material_.particle_wall;
  constexpr int slots = WallHistory::slots;
  int new_wall[slots];
  Vector3d new_shear[slots];
  int used = 0;
  const double ri = p.radius[i];
  for (auto q = list.wall_start[i]; q < list.wall_start[i + 1]; ++q) {
    const int k = static_cast<int>(list.wall_id[q]);
    WallContact wc;
    if (!ctx.walls.contact(k, p.x[i], ri, wc)) continue;
    Vector3d shear = Vector3d::Zero();
    for (int s = 0; s < slots; ++s)
      if (hist.wall[i * slots + s] == k) { shear = hist.shear[i * slots + s]; break; }
    const double delta = ri - wc.distance;
    const Vector3d& nrm = wc.normal;
    const Vector3d vc = p.v[i] - ri * p.omega[i].cross(nrm);
    HertzMindlinContact c;
    hertzMindlinContact<Rolling>(params, delta, nrm, vc, p.omega[i], p.mass[i], ri, ctx.dt, shear, c);
    force += c.force;
    torque += -ri * c.n_x_ft + c.roll;
    if (used < slots) {
      new_wall[used] = k;
      new_shear[used] = shear;
      ++used;
    }
    max_overlap = std::max(max_overlap, delta / ri);
    ++contacts;
  }
  for (int s = 0; s < slots; ++s) {
    hist.wall[i * slots + s] = s < used ? new_wall[s] : -1;
    if (s < used) hist.shear[i * slots + s] = new_shear[s];
  }
}

}  // namespace rcfd
