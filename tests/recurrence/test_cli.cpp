// rcfd-solve recurrence: output, stored matrix, SVG, and exit code 2 naming the dataset for bad databases.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <fstream>
#include <sstream>

#include "../fields/FieldTestUtil.hpp"
#include "recurrence/RecurrenceMatrix.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {
struct Result {
  int code = -1;
  std::string out, err;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Result solve(const std::string& args) {
  const std::string out = tempPath("stdout.txt"), err = tempPath("stderr.txt");
  const std::string cmd = std::string(RCFD_BINARY_DIR) + "/rcfd-solve recurrence " + args + " >" + out + " 2>" + err;
  const int status = std::system(cmd.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}
}  // namespace

TEST(RecurrenceCommand, PrintsSummaryStoresMatrixAndDrawsThePlot) {
  const CartesianGrid g = smallGrid(6, 4, 3);
  const int period = 16;
  const std::string db = tempPath("cli.h5"), svg = tempPath("rec.svg");
  writeAnalyticDatabase(db, g, variedFluid(g), 0.005, 120, [&](int n, double t, FieldFrame& f) {
    for (std::int64_t c = 0; c < g.cellCount(); ++c) {
      f.alpha_p[std::size_t(c)] = float(0.3 + 0.2 * std::sin(2.0 * M_PI * n / period + 0.3 * double(c)));
      f.u_p[std::size_t(3 * c + 1)] = float(std::sin(2.0 * M_PI * t / (period * 0.005)));
    }
  }, R"({"probes": [{"name": "spout", "position": [0.0, 0.015, 0.015]}]})");
  const Result r = solve(db + " --svg " + svg);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("frames N = 120"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("lag 16 frames (0.08 s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("spout"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("satisfied"), std::string::npos) << r.out;
  const auto stored = loadRecurrenceMatrix(db, 120);
  ASSERT_TRUE(stored.has_value());
  EXPECT_EQ(stored->R(3, 3 + period), stored->R(3 + period, 3));
  EXPECT_GT(stored->R(3, 3 + period), 0.999f);
  const std::string picture = slurp(svg);
  EXPECT_NE(picture.find("<svg"), std::string::npos);
  EXPECT_NE(picture.find("t_i [s]"), std::string::npos);
  EXPECT_NE(picture.find("data:image/png;base64,iVBORw0KGgo"), std::string::npos);  // PNG signature

  const Result l1 = solve(db + " --norm l1 --field u_p.y --all-cells --no-store --json");
  ASSERT_EQ(l1.code, 0) << l1.err;
  EXPECT_NE(l1.out.find("\"norm\":\"l1\""), std::string::npos) << l1.out;
  EXPECT_NE(l1.out.find("all "), std::string::npos);
  EXPECT_EQ(loadRecurrenceMatrix(db, 120)->norm, RecurrenceNorm::L2);  // --no-store kept the L2 matrix
}

TEST(RecurrenceCommand, BadDatabasesExitWithCode2NamingTheDataset) {
  struct Case {
    std::function<void(RawSpec&)> breakIt;
    const char* name;
  };
  for (const Case& c : {Case{[](RawSpec& s) { s.omit = "/frames/alpha_p"; }, "/frames/alpha_p"},
                        Case{[](RawSpec& s) { s.alphaExtraX = 2; }, "/frames/alpha_p"},
                        Case{[](RawSpec& s) { s.nanFrame = 1; }, "/frames/u_p"},
                        Case{[](RawSpec& s) { s.frames = 2; }, "/frames"},
                        Case{[](RawSpec& s) { s.spacing = {0.01, 0.0, 0.01}; }, "/grid@spacing"}}) {
    RawSpec spec;
    c.breakIt(spec);
    const std::string db = tempPath("bad-cli.h5");
    writeRawDatabase(db, spec);
    const Result r = solve(db);
    EXPECT_EQ(r.code, 2) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.name), std::string::npos) << r.err;
  }
  const Result missing = solve(tempPath("no-such.h5"));
  EXPECT_EQ(missing.code, 2);
  const std::string db = writeWavyDatabase("ok.h5", smallGrid(), 5);
  EXPECT_EQ(solve(db + " --norm l3").code, 2);
  EXPECT_EQ(solve(db + " --field alpha_g").code, 2);
  EXPECT_EQ(solve(db + " --probe 1,2").code, 2);
}
