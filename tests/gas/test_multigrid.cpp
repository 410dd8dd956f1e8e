// The pressure CG's multigrid preconditioner on a grid large enough for the hybrid (slab-parallel)
// Gauss-Seidel of its finest level: a symmetric operator (CG needs it), an effective one, and the same
// bits for any number of threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/IterativeLinearSolvers>
#include <random>

#include "cfddem/gas/AggregationMultigrid.hpp"

namespace rcfd {
namespace {

using gas::AggregationMultigrid;

/// 7-point Laplacian on nx x ny x nz cells with unit spacing, a fixed value (Dirichlet) below the
/// bottom row, zero flux elsewhere, and cells of lower conductance in a band (as alpha_G does).
struct PoissonCase {
  int nx = 30, ny = 48, nz = 14;  // 20,160 unknowns: above the hybrid smoother's threshold
  AggregationMultigrid::Matrix a;
  std::vector<std::array<int, 3>> cells;

  PoissonCase() {
    const int n = nx * ny * nz;
    auto index = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
    auto conductance = [&](int j) { return j > ny / 3 && j < ny / 2 ? 0.2 : 1.0; };
    std::vector<Eigen::Triplet<double>> t;
    cells.resize(std::size_t(n));
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const int r = index(i, j, k);
          cells[std::size_t(r)] = {i, j, k};
          double diag = j == 0 ? 2.0 * conductance(j) : 0.0;
          const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
          for (const auto& q : nb) {
            if (q[0] < 0 || q[0] >= nx || q[1] < 0 || q[1] >= ny || q[2] < 0 || q[2] >= nz) continue;
            const double c = std::min(conductance(j), conductance(q[1]));
            diag += c;
            t.emplace_back(r, index(q[0], q[1], q[2]), -c);
          }
          t.emplace_back(r, r, diag);
        }
    a.resize(n, n);
    a.setFromTriplets(t.begin(), t.end());
  }
};

Eigen::VectorXd randomVector(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

TEST(Multigrid, HybridSmootherKeepsTheCycleSymmetric) {
  PoissonCase p;
  AggregationMultigrid mg(p.cells);
  mg.compute(p.a);
  ASSERT_GT(mg.levels(), 2);
  const int n = int(p.a.rows());
  const Eigen::VectorXd u = randomVector(n, 1), v = randomVector(n, 2);
  Eigen::VectorXd mu, mv;
  mg.apply(u, mu);
  mg.apply(v, mv);
  // <v, M^-1 u> = <u, M^-1 v>: a forward hybrid sweep before and its transpose, the backward one, after.
  EXPECT_NEAR(v.dot(mu), u.dot(mv), 1e-11 * std::abs(u.dot(mv)));
  EXPECT_GT(u.dot(mu), 0.0);  // positive definite along u
}

/// Plain PCG with the multigrid, as PressureSolver runs it; returns the iterations to |r| <= tol |b|.
int pcgIterations(const AggregationMultigrid& mg, const AggregationMultigrid::Matrix& a, const Eigen::VectorXd& b,
                  double tol, Eigen::VectorXd& x) {
  x.setZero(b.size());
  Eigen::VectorXd r = b, z, p, q;
  mg.apply(r, z);
  p = z;
  double rz = r.dot(z);
  for (int it = 1; it <= 200; ++it) {
    q = a * p;
    const double alpha = rz / p.dot(q);
    x += alpha * p;
    r -= alpha * q;
    if (r.norm() <= tol * b.norm()) return it;
    mg.apply(r, z);
    const double rzNew = r.dot(z);
    p = z + (rzNew / rz) * p;
    rz = rzNew;
  }
  return 201;
}

TEST(Multigrid, PreconditionedCgConvergesInFewIterationsAndIsThreadIndependent) {
  PoissonCase p;
  AggregationMultigrid mg(p.cells);
  mg.compute(p.a);
  const Eigen::VectorXd b = randomVector(int(p.a.rows()), 3);
  const int threads = omp_get_max_threads();
  Eigen::VectorXd x1, x2;
  omp_set_num_threads(1);
  const int it1 = pcgIterations(mg, p.a, b, 1e-10, x1);
  omp_set_num_threads(2);
  const int it2 = pcgIterations(mg, p.a, b, 1e-10, x2);
  omp_set_num_threads(threads);
  EXPECT_LE(it1, 25);
  EXPECT_EQ(it1, it2);
  EXPECT_EQ((x1 - x2).cwiseAbs().maxCoeff(), 0.0);  // the slabs are fixed by the grid, not the threads
  EXPECT_LE((b - p.a * x1).norm(), 1e-9 * b.norm());
}

}  // namespace
}  // namespace rcfd
