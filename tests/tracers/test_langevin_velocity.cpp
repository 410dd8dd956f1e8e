// langevin_velocity: the Ornstein-Uhlenbeck fluctuation on the frames' velocity variance. The exact
// step (OrnsteinUhlenbeckStep) against a finely resolved OU process. On a bed at rest with a uniform
// variance, the tracers' mean fluctuation over a step has the variance and lag-one correlation of the
// integrated OU process, T the kinetic-theory time between collisions in a dense bed and
// rcfd.langevin_time in a dilute one, and where T is far below the step the tracers spread with the
// diffusivity sigma^2 T; where alpha_P^rec and the variance vary across the box, the drift keeps the
// tracers distributed as alpha_P^rec, and it takes no gradient through a draft plate; the count is kept,
// results are bit-identical for 1 and 2 threads and across a resume, a database without the velocity
// spread leaves the tracers as without the effect, and a scene without the effect allocates nothing for it. The normal numbers come from a
// table of quantiles (NormalTable).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <numbers>

#include "TracerTestSupport.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/NormalTable.hpp"
#include "tracers/OrnsteinUhlenbeckStep.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

const std::vector<std::string> kLangevin = {"transport", "walls", "tracer_volume_fraction", "langevin_velocity"};

/// A 0.1 x 0.1 x 0.02 m box of 1 cm cells at rest (u_P^rec = 0). alpha(x) and the variance per
/// component sigma2(x) as functions of the cell centre's x in [-0.05, 0.05].
struct RestingBox {
  Scene scene;
  std::shared_ptr<FieldDatabase> db;
  template <class Alpha, class Sigma2>
  RestingBox(std::vector<std::string> effects, double time, long tracers, Alpha alpha, Sigma2 sigma2,
             bool withSpread = true, double depth = 0.02) {
    scene = boxScene({0.1, 0.1, depth}, 0.01, tracers, 0.005, std::move(effects), 0.3);
    scene.rcfd.langevin_time = time;
    const CartesianGrid grid = gridOf(scene);
    db = database(scene, 400, scene.rcfd.dt, [=](int, double, FieldFrame& f) {
      const std::size_t cells = std::size_t(grid.cellCount());
      if (withSpread) {
        f.up_fraction.assign(cells, 0.5f);
        f.u_p_up.assign(3 * cells, 0.0f);
        f.u_p_down.assign(3 * cells, 0.0f);
        f.u_p_variance.assign(3 * cells, 0.0f);
      }
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
        const auto ijk = grid.cellIjk(c);
        const double x = grid.cellCenter(ijk[0], ijk[1], ijk[2]).x();
        f.alpha_p[std::size_t(c)] = float(alpha(x));
        if (withSpread)
          for (int d = 0; d < 3; ++d) f.u_p_variance[3 * std::size_t(c) + std::size_t(d)] = float(sigma2(x));
      }
    });
  }
};

std::unique_ptr<TracerSimulation> runBox(const RestingBox& box, std::int64_t steps, int threads = 2,
                                         std::int64_t checkpointAt = -1) {
  return runSteps(box.scene, box.db, 5, steps, threads, checkpointAt, "langevin-checkpoint.h5");
}

double uniformAlpha(double) { return 0.3; }

}  // namespace

/// Variance and lag-one correlation of the mean fluctuation over a step (what moves the tracer) on a
/// bed at rest of uniform alpha_P and variance: for the OU process of memory T integrated over dt,
/// 2 sigma^2 (tau - 1 + a) / tau^2 and (1 - a)^2 / (2 (tau - 1 + a)), tau = dt / T, a = exp(-tau).
static void expectOrnsteinUhlenbeck(double alpha, double sigma, double memory, double expectedTime) {
  RestingBox box(kLangevin, memory, 20000, [=](double) { return alpha; }, [&](double) { return sigma * sigma; }, true, 0.1);
  omp_set_num_threads(2);
  const RecurrencePath path = sequentialPath(box.db->frameCount(), 102);
  TracerSimulation sim(box.scene, box.db, path, TracerRunSettings{5, 100, 0});
  for (int k = 0; k < 40; ++k) sim.step();  // 10 T
  const auto& u = sim.context().streamVelocity;
  const std::size_t n = sim.cloud().size();
  // streamVelocity is per index; the cloud may be reordered between steps, so pair by id.
  auto byId = [&](int d) { return sim.cloud().inIdOrder(std::vector<float>(u[d].begin(), u[d].end())); };
  const std::vector<float> before[3] = {byId(0), byId(1), byId(2)};
  // Tracers 5 mm or more from every wall: no reflection of their fluctuation in the step.
  const auto& cloud = sim.cloud();
  const auto x = cloud.inIdOrder(cloud.x), y = cloud.inIdOrder(cloud.y), z = cloud.inIdOrder(cloud.z);
  std::vector<char> interior(n);
  for (std::size_t i = 0; i < n; ++i)
    interior[i] = std::abs(x[i]) < 0.045 && y[i] > 0.005 && y[i] < 0.095 && z[i] > 0.02 && z[i] < 0.08;
  sim.step();
  const std::vector<float> after[3] = {byId(0), byId(1), byId(2)};
  for (int d = 0; d < 3; ++d) {
    double mean = 0.0, var = 0.0, cov = 0.0, count = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!interior[i]) continue;
      mean += after[d][i];
      var += double(after[d][i]) * double(after[d][i]);
      cov += double(after[d][i]) * double(before[d][i]);
      count += 1.0;
    }
    ASSERT_GT(count, 0.3 * double(n));
    mean /= count;
    var = var / count - mean * mean;
    cov /= count;
    EXPECT_NEAR(mean, 0.0, 4.0 * sigma / std::sqrt(count)) << d;
    const double tau = 0.005 / expectedTime, a = std::exp(-tau);
    const double variance = 2.0 * sigma * sigma * (tau - 1.0 + a) / (tau * tau);
    EXPECT_NEAR(var, variance, 0.04 * variance) << d;
    EXPECT_NEAR(cov / var, (1.0 - a) * (1.0 - a) / (2.0 * (tau - 1.0 + a)), 0.02) << d;
  }
}

TEST(OrnsteinUhlenbeckStep, MatchesTheProcessResolvedInAThousandSubSteps) {
  // For dt / T from 1e-3 to 30: the end velocity and the mean over the step of 40,000 OU paths stepped
  // 1,000 times within dt (Euler-Maruyama, each sub-step an exact OU step) against the one exact step.
  for (const double tau : {1e-3, 0.05, 1.0, 30.0}) {
    const double dt = 1.0, memory = dt / tau;
    const OrnsteinUhlenbeckStep exact = OrnsteinUhlenbeckStep::over(dt, memory);
    const OrnsteinUhlenbeckStep fine = OrnsteinUhlenbeckStep::over(dt / 1000.0, memory);
    const NormalTable& normals = NormalTable::instance();
    double s[2][2] = {}, m[2] = {}, e[2][2] = {}, em[2] = {};
    const int paths = 40000;
    for (int p = 0; p < paths; ++p) {
      CounterRng rng(CounterRngPrefix(7, RngPurpose::Langevin, std::uint64_t(p)), 1);
      double xi[3];
      normals.three(rng.nextU64(), xi);
      const double start = xi[0];  // stationary: unit variance
      double u = start, sum = 0.0;
      for (int k = 0; k < 1000; ++k) {
        normals.three(rng.nextU64(), xi);
        const double next = fine.decay * u + fine.kick * xi[0];
        sum += 0.5 * (u + next) / 1000.0;  // trapezoid: the fine path's mean to O(sub-step^2)
        u = next;
      }
      const double fineValues[2] = {u - exact.decay * start, sum - exact.carry * start};
      normals.three(rng.nextU64(), xi);
      const double exactValues[2] = {exact.kick * xi[1], exact.shared * xi[1] + exact.own * xi[2]};
      for (int i = 0; i < 2; ++i) {
        m[i] += fineValues[i], em[i] += exactValues[i];
        for (int j = 0; j < 2; ++j) s[i][j] += fineValues[i] * fineValues[j], e[i][j] += exactValues[i] * exactValues[j];
      }
    }
    // The noise given the start velocity: same (zero) means, variances and covariance.
    for (int i = 0; i < 2; ++i) {
      const double scale = std::sqrt(e[i][i] / paths);
      EXPECT_NEAR(m[i] / paths, 0.0, 4.0 * scale / std::sqrt(paths)) << tau;
      EXPECT_NEAR(em[i] / paths, 0.0, 4.0 * scale / std::sqrt(paths)) << tau;
      for (int j = 0; j < 2; ++j) {
        const double tolerance = 0.05 * std::sqrt(e[i][i] * e[j][j]) / paths;
        EXPECT_NEAR(s[i][j] / paths, e[i][j] / paths, tolerance) << "tau " << tau << " entry " << i << j;
      }
    }
    // And the closed forms: the mean over the step of a stationary path has variance 2 (tau - 1 + a) / tau^2.
    const double a = std::exp(-tau);
    EXPECT_NEAR(exact.carry * exact.carry + exact.shared * exact.shared + exact.own * exact.own,
                2.0 * (tau - 1.0 + a) / (tau * tau), 1e-9 * (1.0 + 1.0 / tau)) << tau;
  }
}

TEST(LangevinVelocity, TheFluctuationHasTheCellsVarianceAndTheOrnsteinUhlenbeckMemory) {
  // dt = 5 ms, sigma = 0.2 m/s. Dilute (alpha_P = 1e-3: a collision every 0.7 s): the memory is
  // rcfd.langevin_time, 0.02 s.
  expectOrnsteinUhlenbeck(1e-3, 0.2, 0.02, 0.02);
  // Dense (alpha_P = 0.05, d_P = 1.8 mm): the time between collisions d sqrt(pi) / (24 alpha g0 sigma),
  // g0 = (1 - alpha/2) / (1 - alpha)^3 = 1.137, is 11.7 ms, below the 0.3 s cap.
  const double alpha = 0.05, g0 = (1.0 - 0.5 * alpha) / std::pow(1.0 - alpha, 3);
  const double collisions = 1.8e-3 * std::sqrt(std::numbers::pi) / (24.0 * alpha * g0 * 0.2);
  EXPECT_NEAR(collisions, 0.0117, 0.0001);
  expectOrnsteinUhlenbeck(alpha, 0.2, 0.3, collisions);
}

TEST(LangevinVelocity, WhereTheMemoryIsFarBelowTheStepTracersSpreadWithSigmaSquaredTimesTheMemory) {
  // A dense bed at rest (alpha_P = 0.3, sigma = 0.2 m/s): the time between collisions is 0.89 ms, a
  // sixth of the 5 ms step. Over 0.4 s the tracers' mean square displacement per component is
  // 2 sigma^2 T t (less T (1 - exp(-t / T)), negligible here), not the sigma^2 dt t of a fluctuation
  // drawn afresh and held over each step, 2.8 times as much.
  const double alpha = 0.3, sigma = 0.2, g0 = (1.0 - 0.5 * alpha) / std::pow(1.0 - alpha, 3);
  const double memory = 1.8e-3 * std::sqrt(std::numbers::pi) / (24.0 * alpha * g0 * sigma);
  EXPECT_NEAR(memory, 8.9e-4, 0.1e-4);
  RestingBox box(kLangevin, 0.3, 20000, [=](double) { return alpha; }, [=](double) { return sigma * sigma; });
  box.scene.rcfd.d0 = 0.0;  // the Langevin spread alone
  omp_set_num_threads(2);
  const RecurrencePath path = sequentialPath(box.db->frameCount(), 102);
  TracerSimulation sim(box.scene, box.db, path, TracerRunSettings{5, 100, 0});
  const auto x0 = sim.cloud().inIdOrder(sim.cloud().x), y0 = sim.cloud().inIdOrder(sim.cloud().y);
  const int steps = 80;
  for (int k = 0; k < steps; ++k) sim.step();
  const auto x = sim.cloud().inIdOrder(sim.cloud().x), y = sim.cloud().inIdOrder(sim.cloud().y);
  double squares = 0.0, count = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    // Tracers that started 1.5 cm or more from the side walls: none reaches them (rms 2.4 mm).
    if (std::abs(x0[i]) > 0.035 || y0[i] < 0.015 || y0[i] > 0.085) continue;
    squares += (x[i] - x0[i]) * (x[i] - x0[i]) + (y[i] - y0[i]) * (y[i] - y0[i]);
    count += 2.0;
  }
  ASSERT_GT(count, 8000.0);
  const double t = steps * 0.005;
  const double expected = 2.0 * sigma * sigma * memory * (t - memory * (1.0 - std::exp(-t / memory)));
  EXPECT_NEAR(squares / count, expected, 0.06 * expected);
}

/// After 400 steps (2 s) on a bed at rest whose alpha_P and variance vary across x, each column of
/// cells holds its share of the tracers: columns 1-7 within 10 %, column 8 within `besideWall`, the two
/// at the walls (where the drift comes from a one-sided difference) within `atWall`.
template <class Alpha, class Sigma2>
static void expectKeepsAlphaRec(Alpha alpha, Sigma2 sigma2, double besideWall, double atWall) {
  const RestingBox box(kLangevin, 0.02, 40000, alpha, sigma2);
  const auto sim = runBox(box, 400);
  const auto& ctx = sim->context();
  std::vector<double> column(10, 0.0), expected(10, 0.0);
  for (std::size_t i = 0; i < sim->cloud().size(); ++i) {
    const int k = std::clamp(int((sim->cloud().x[i] + 0.05) / 0.01), 0, 9);
    column[std::size_t(k)] += 1.0;
  }
  double total = 0.0;
  for (int k = 0; k < 10; ++k) total += expected[std::size_t(k)] = alpha(-0.045 + 0.01 * k);
  for (int k = 0; k < 10; ++k) {
    const double share = column[std::size_t(k)] / double(sim->cloud().size());
    const double want = expected[std::size_t(k)] / total;
    const double tolerance = k == 0 || k == 9 ? atWall : k == 8 ? besideWall : 0.1;
    EXPECT_NEAR(share, want, tolerance * want) << "column " << k;
  }
  EXPECT_EQ(sim->cloud().size(), std::size_t(40000));
  EXPECT_EQ(ctx.streamVelocity[0].size(), std::size_t(40000));
}

TEST(LangevinVelocity, TheDriftKeepsTracersDistributedAsAlphaRecWhereAlphaAndTheVarianceVary) {
  // alpha from 0.05 to 0.01 across x and a variance 16 times larger on the dense side: without the
  // drift the tracers would gather where they move least. The memory is 10-20 ms, two to four steps.
  // The columns at the walls hold 9-18 % too few.
  expectKeepsAlphaRec([](double x) { return 0.03 - 0.4 * x; },
                      [](double x) { return std::pow(0.05 + 0.2 * (0.5 - 10.0 * x), 2); }, 0.1, 0.25);
}

TEST(LangevinVelocity, TheDriftKeepsTracersDistributedAsAlphaRecWhereTheMemoryIsFarBelowTheStep) {
  // A dense bed: alpha from 0.35 to 0.1 across x, sigma from 0.5 to 0.05 m/s. The memory runs from
  // 0.25 ms (a twentieth of the step) on the dense side to 20 ms; the drift must then hold the
  // gradient of sigma^2 T, not only T times that of sigma^2 (with only the latter, column 1 holds
  // more than 10 % too many). Near the dilute wall, where T changes fastest, the wall column holds
  // 28 % too few and the one beside it 13 % too many.
  expectKeepsAlphaRec([](double x) { return 0.225 - 2.5 * x; },
                      [](double x) { return std::pow(0.275 - 4.5 * x, 2); }, 0.16, 0.32);
}

namespace {
/// One tracer at rest on the annulus's side of the right draft plate of the ProCell prism on 10 mm cells
/// (the plate, x 0.0225 to 0.0245, snapped to the face x = 0.025), 1 mm from the plate. The annulus's
/// cells are dense and still (alpha_P 0.6, no variance); the tube's cells dilute and agitated (alpha_P
/// 0.05, sigma 0.2 m/s). Returns its displacement along x over ten steps of 5 ms.
double driftBesideThePlate() {
  Scene s = boxScene({0.2, 0.2, 0.2}, 0.01, 1, 0.005, kLangevin);
  s.apparatus = Scene{}.apparatus;  // ProCell
  s.apparatus.draft_plates = DraftPlatesSpec{0.06, 0.045, 0.035, 0.002};
  s.process.bed_mass = Scene{}.process.bed_mass;
  s.rcfd.d0 = 0.0;
  const CartesianGrid grid = gridOf(s);
  const double face = 0.025;
  auto db = database(s, 3, s.rcfd.dt, [grid, face](int, double, FieldFrame& f) {
    const std::size_t cells = std::size_t(grid.cellCount());
    zeroVelocitySpread(f, cells);
    for (std::size_t c = 0; c < cells; ++c) {
      const auto ijk = grid.cellIjk(std::int64_t(c));
      const bool tube = std::abs(grid.cellCenter(ijk[0], ijk[1], ijk[2]).x()) < face;
      f.alpha_p[c] = tube ? 0.05f : 0.6f;
      for (std::size_t d = 0; d < 3; ++d) f.u_p_variance[3 * c + d] = tube ? 0.04f : 0.0f;
    }
  });
  TracerSimulation sim(s, db, sequentialPath(3, 12), {5, 1, 0});
  const Eigen::Vector3d start(face + 0.0005, 0.06, 0.5 * Apparatus(s.apparatus).depth());
  sim.context().cloud.setPosition(0, start);
  for (int k = 0; k < 10; ++k) sim.step();
  return sim.cloud().position(0).x() - start.x();
}
}  // namespace

TEST(LangevinVelocity, NoDriftAcrossAPlate) {
  // The drift T grad(alpha sigma^2) / alpha of the annulus's cell beside the plate is taken on its own
  // side: the still annulus gives its tracer no motion. Taken through the plate, the tube's agitation
  // drove it 0.2 mm against the plate within ten steps.
  EXPECT_EQ(driftBesideThePlate(), 0.0);
}

TEST(LangevinVelocity, BitIdenticalForOneAndTwoThreadsAndAcrossAResume) {
  const RestingBox box(kLangevin, 0.02, 20000, [](double) { return 0.02; }, [](double x) { return 0.01 + x * x * 10.0; });
  const auto two = runBox(box, 60, 2);
  const auto one = runBox(box, 60, 1);
  const auto resumed = runBox(box, 60, 2, 23);
  EXPECT_EQ(two->cloud().x, one->cloud().x);
  EXPECT_EQ(two->cloud().y, one->cloud().y);
  EXPECT_EQ(two->cloud().x, resumed->cloud().x);
  EXPECT_EQ(two->cloud().z, resumed->cloud().z);
}

TEST(LangevinVelocity, WithoutTheVelocitySpreadTracersMoveAsWithoutItAndTheSummarySaysSo) {
  // A moving bed (u_P^rec = 0.1 m/s along x) of a database without the spread.
  auto flowing = [](std::vector<std::string> effects) {
    RestingBox box(std::move(effects), 0.02, 4000, uniformAlpha, [](double) { return 0.01; }, false);
    const CartesianGrid grid = gridOf(box.scene);
    box.db = database(box.scene, 40, box.scene.rcfd.dt, [=](int, double, FieldFrame& f) {
      std::fill(f.alpha_p.begin(), f.alpha_p.end(), 0.3f);
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) f.u_p[3 * std::size_t(c)] = 0.1f;
    });
    return box;
  };
  const auto listed = runBox(flowing(kLangevin), 30);
  const auto plain = runBox(flowing({"transport", "walls", "tracer_volume_fraction"}), 30);
  EXPECT_EQ(listed->cloud().inIdOrder(listed->cloud().x), plain->cloud().inIdOrder(plain->cloud().x));
  h5::File out(tempPath("langevin-result.h5"), h5::File::Mode::Create);
  nlohmann::json summary;
  listed->writeResults(out, summary);
  EXPECT_EQ(summary["langevin_velocity"]["active"], false);
  EXPECT_NE(summary["langevin_velocity"]["note"].get<std::string>().find("u_p_variance"), std::string::npos);
}

TEST(LangevinVelocity, AllocatesOnlyWhenListed) {
  const RestingBox with(kLangevin, 0.02, 2000, uniformAlpha, [](double) { return 0.01; });
  const auto listed = runBox(with, 1);
  EXPECT_GT(listed->allocatedBytes("langevin_velocity"), 2000 * 3 * sizeof(float));
  const RestingBox without({"transport", "walls", "tracer_volume_fraction"}, 0.02, 2000, uniformAlpha,
                           [](double) { return 0.01; });
  const auto plain = runBox(without, 1);
  EXPECT_EQ(plain->allocatedBytes("langevin_velocity"), 0u);
  EXPECT_TRUE(plain->context().streamVelocity[0].empty());
}

TEST(NormalTable, ThreeIndependentNumbersOfMeanZeroAndUnitVarianceFromOneDraw) {
  const auto& table = NormalTable::instance();
  double mean = 0.0, var = 0.0, fourth = 0.0, lo = 0.0, hi = 0.0;
  for (const float z : table.values()) {
    mean += z, var += double(z) * z, fourth += std::pow(double(z), 4);
    lo = std::min(lo, double(z)), hi = std::max(hi, double(z));
  }
  const double n = double(NormalTable::kSize);
  EXPECT_NEAR(mean / n, 0.0, 1e-6);
  EXPECT_NEAR(var / n, 1.0, 1e-6);
  EXPECT_NEAR(fourth / n, 3.0, 0.05);  // the Gaussian's kurtosis, less its tails beyond 3.7
  EXPECT_NEAR(hi, -lo, 1e-6);
  EXPECT_GT(hi, 3.5);
  // The three numbers of one counter-based draw are uncorrelated.
  double c01 = 0.0, c12 = 0.0, c02 = 0.0;
  const int draws = 200000;
  for (int i = 0; i < draws; ++i) {
    CounterRng rng(9, RngPurpose::Test, std::uint64_t(i), 3);
    double xi[3];
    table.three(rng.nextU64(), xi);
    c01 += xi[0] * xi[1], c12 += xi[1] * xi[2], c02 += xi[0] * xi[2];
  }
  for (const double c : {c01, c12, c02}) EXPECT_NEAR(c / draws, 0.0, 5.0 / std::sqrt(double(draws)));
}
