#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "SceneTestUtil.hpp"
#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"

using namespace rcfd;
using nlohmann::json;
using rcfd::test::readText;
using rcfd::test::sourcePath;

namespace {

json quickScene() { return json::parse(readText(sourcePath("examples/quick.json"))); }

/// The violations' pointers of a job that must be refused.
std::vector<std::string> refusedPointers(const json& job) {
  try {
    loadJob(job, "job");
  } catch (const InputError& e) {
    std::vector<std::string> pointers;
    for (const auto& v : e.violations()) pointers.push_back(v.pointer);
    return pointers;
  }
  ADD_FAILURE() << "job accepted: " << job.dump().substr(0, 200);
  return {};
}

}  // namespace

TEST(Jobs, InlineSceneJobLoads) {
  const JobSpec job = loadJob({{"kind", "spray"}, {"scene", quickScene()}, {"database", "db.h5"},
                               {"duration", 3600.0}, {"seed", 7}, {"checkpoint_interval", 60.0}});
  EXPECT_EQ(job.kind, "spray");
  EXPECT_EQ(job.database, "db.h5");
  EXPECT_DOUBLE_EQ(job.duration, 3600.0);
  EXPECT_EQ(job.seed, 7u);
  EXPECT_EQ(job.scene.name, "quick");
  EXPECT_EQ(job.scene.rcfd.tracers, 20000);
}

TEST(Jobs, SceneFileIsResolvedRelativeToTheJob) {
  const auto dir = std::filesystem::temp_directory_path() / ("rcfd-test-jobs-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(sourcePath("examples/quick.json"), dir / "scene.json",
                             std::filesystem::copy_options::overwrite_existing);
  {
    std::ofstream(dir / "job.json") << R"({"kind": "calibration", "scene_file": "scene.json", "database": "db.h5",
        "duration": 35, "d0_values": [0, 1e-5, 1e-4, 5e-4], "discard": 5})";
  }
  const JobSpec job = loadJobFile((dir / "job.json").string());
  EXPECT_EQ(job.kind, "calibration");
  EXPECT_EQ(job.scene.name, "quick");
  EXPECT_EQ(job.d0_values, (std::vector<double>{0, 1e-5, 1e-4, 5e-4}));
  EXPECT_DOUBLE_EQ(job.discard, 5.0);

  // A database job needs neither a database nor a duration.
  const JobSpec db = loadJob({{"kind", "database"}, {"scene_file", "scene.json"}}, "job", dir.string());
  EXPECT_EQ(db.kind, "database");
  EXPECT_TRUE(db.database.empty());
  std::filesystem::remove_all(dir);
}

TEST(Jobs, InvalidJobsAreRefusedWithPointers) {
  const json scene = quickScene();
  using V = std::vector<std::string>;
  EXPECT_EQ(refusedPointers({{"kind", "spray"}, {"scene", scene}, {"duration", 10.0}}), V{"/database"});
  EXPECT_EQ(refusedPointers({{"kind", "database"}, {"scene", scene}, {"scene_file", "x.json"}}), V{"/scene_file"});
  EXPECT_EQ(refusedPointers({{"kind", "database"}}), V{"/scene"});
  EXPECT_EQ(refusedPointers({{"kind", "simulate"}, {"scene", scene}}), V{"/kind"});
  EXPECT_EQ(refusedPointers({{"scene", scene}}), V{"/kind"});
  EXPECT_EQ(refusedPointers({{"kind", "spray"}, {"scene", scene}, {"database", "d"}, {"duration", 1.0},
                             {"d0_values", {1e-4}}}),
            V{"/d0_values"});
  EXPECT_EQ(refusedPointers({{"kind", "spray"}, {"scene", scene}, {"database", "d"}, {"duration", -1.0}}),
            V{"/duration"});
  EXPECT_EQ(refusedPointers({{"kind", "database"}, {"scene", scene}, {"seed", -3}}), V{"/seed"});
  EXPECT_EQ(refusedPointers({{"kind", "database"}, {"scene", scene}, {"priority", 1}}), V{"/priority"});
  EXPECT_EQ(refusedPointers({{"kind", "database"}, {"scene_file", "/nonexistent/scene.json"}}), V{"/scene_file"});

  json bad = scene;
  bad["spray"]["cone_half_angle_deg"] = 95;
  EXPECT_EQ(refusedPointers({{"kind", "database"}, {"scene", bad}}), V{"/scene/spray/cone_half_angle_deg"});
  bad = scene;
  bad["spray"]["spray_zone"]["y_min"] = 0.5;  // a semantic rule, prefixed too
  EXPECT_EQ(refusedPointers({{"kind", "database"}, {"scene", bad}}), V{"/scene/spray/spray_zone/y_min"});
}

TEST(Jobs, SchemaTextsAreServed) {
  EXPECT_NE(schemaText("scene").find("\"effects\""), std::string::npos);
  EXPECT_NE(schemaText("job").find("\"scene_file\""), std::string::npos);
  EXPECT_THROW(schemaText("nonsense"), std::out_of_range);
}

TEST(Jobs, MessagesSayWhatIsWrong) {
  json scene = quickScene();
  scene["effects"].push_back("bogus");
  try {
    loadJob({{"kind", "spray"}, {"scene", scene}, {"database", "d"}, {"duration", 1.0}, {"discard", 2.0}}, "job");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 2u) << e.what();
    const std::string text = e.what();
    EXPECT_NE(text.find("/discard: only calibration jobs take \"discard\" (not)"), std::string::npos) << text;
    EXPECT_NE(text.find("/scene/effects/16: unknown effect \"bogus\""), std::string::npos) << text;
  }
}
