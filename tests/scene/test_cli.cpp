// Runs the built rcfd-solve: `validate` exits 0 on every example and 2 with the pointer on stderr on
// a bad scene; `list-effects` prints every effect of the schema.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "SceneTestUtil.hpp"

namespace {

struct Outcome {
  int exitCode;
  std::string out, err;
};

Outcome run(const std::string& arguments) {
  const std::string binary = std::string(RCFD_BINARY_DIR) + "/rcfd-solve";
  const auto base = std::filesystem::temp_directory_path() / ("rcfd-test-cli-" + std::to_string(::getpid()));
  const std::string out = base.string() + ".out", err = base.string() + ".err";
  const int status = std::system((binary + " " + arguments + " >" + out + " 2>" + err).c_str());
  Outcome o{WIFEXITED(status) ? WEXITSTATUS(status) : -1, rcfd::test::readText(out), rcfd::test::readText(err)};
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return o;
}

bool haveBinary() { return std::filesystem::exists(std::string(RCFD_BINARY_DIR) + "/rcfd-solve"); }

}  // namespace

TEST(Cli, ValidateAcceptsEveryExample) {
  if (!haveBinary()) GTEST_SKIP() << "rcfd-solve not built";
  for (const auto& file : rcfd::test::exampleFiles()) {
    const Outcome o = run("validate " + file);
    EXPECT_EQ(o.exitCode, 0) << file << "\n" << o.err;
    EXPECT_EQ(o.out.rfind("valid scene: ", 0), 0u) << o.out;
  }
}

TEST(Cli, ValidateRefusesABadSceneWithItsPointer) {
  if (!haveBinary()) GTEST_SKIP() << "rcfd-solve not built";
  const Outcome o = run("validate " + rcfd::test::sourcePath("tests/data/bad_scenes/cone_angle_95.json"));
  EXPECT_EQ(o.exitCode, 2);
  EXPECT_NE(o.err.find("/spray/cone_half_angle_deg: 95 is not < 90"), std::string::npos) << o.err;
  const Outcome empty = run("validate " + rcfd::test::sourcePath("tests/data/bad_scenes/empty.json"));
  EXPECT_EQ(empty.exitCode, 2);
  const Outcome missing = run("validate /nonexistent/scene.json");
  EXPECT_EQ(missing.exitCode, 2);
}

TEST(Cli, ValidateTellsJobsFromScenes) {
  if (!haveBinary()) GTEST_SKIP() << "rcfd-solve not built";
  const auto job = std::filesystem::temp_directory_path() / ("rcfd-test-cli-job-" + std::to_string(::getpid()) + ".json");
  {
    std::ofstream(job) << R"({"kind": "database", "scene_file": ")" << rcfd::test::sourcePath("examples/quick.json")
                       << R"("})";
  }
  const Outcome o = run("validate " + job.string());
  EXPECT_EQ(o.exitCode, 0) << o.err;
  EXPECT_EQ(o.out.rfind("valid job: database", 0), 0u) << o.out;
  {
    std::ofstream(job) << R"({"kind": "spray", "scene_file": "x.json"})";
  }
  const Outcome bad = run("validate " + job.string());
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_NE(bad.err.find("/database"), std::string::npos) << bad.err;
  std::filesystem::remove(job);
}

TEST(Cli, ListEffectsPrintsTheVocabulary) {
  if (!haveBinary()) GTEST_SKIP() << "rcfd-solve not built";
  const Outcome o = run("list-effects");
  EXPECT_EQ(o.exitCode, 0);
  for (const char* name : {"gas", "transport", "fluctuation", "directed_relaxation", "langevin_velocity", "free_flight", "velocity_streams", "deposition", "coverage",
                           "deposition_maps"}) {
    EXPECT_NE(o.out.find(std::string("\n  ") + name + " "), std::string::npos) << name;
  }
  EXPECT_NE(o.out.find("spray.deposition_model: exponential | linear_clipped"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("rcfd.fluctuation_model: lichtenegger_pirker | cfdem"), std::string::npos) << o.out;
  const Outcome j = run("list-effects --json");
  const auto list = nlohmann::json::parse(j.out);
  ASSERT_EQ(list["effects"].size(), 19u);
  EXPECT_EQ(list["effects"][0]["name"], "gas");
  EXPECT_EQ(list["effects"][0]["stage"], "cfd_dem");
  bool apparatus = false;
  for (const auto& m : list["models"]) apparatus = apparatus || m["key"] == "apparatus.type";
  EXPECT_TRUE(apparatus);
}
