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

TEST(Jobs, ScenePatchChangesTheSceneOfThisJobOnly) {
  const json patch = {{"dem", {{"sample_duration", 10.0}, {"reference_duration", 10.0}}}, {"name", "quick-10s"}};
  // On a scene file, resolved relative to the job (the example job's own layout).
  const JobSpec fromFile = loadJob({{"kind", "database"}, {"scene_file", "../quick.json"}, {"scene_patch", patch}}, "job",
                                   sourcePath("examples/jobs"));
  EXPECT_EQ(fromFile.scene.name, "quick-10s");
  EXPECT_DOUBLE_EQ(fromFile.scene.dem.sample_duration, 10.0);
  EXPECT_DOUBLE_EQ(fromFile.scene.dem.reference_duration, 10.0);
  EXPECT_DOUBLE_EQ(fromFile.scene.dem.warmup, 1.0);  // untouched keys stay the file's
  EXPECT_EQ(fromFile.scene.rcfd.tracers, 20000);
  // The scene a result records is the patched one.
  EXPECT_DOUBLE_EQ(json::parse(fromFile.scene.source_json)["dem"]["sample_duration"].get<double>(), 10.0);
  // Inline, and null removes a key (merge-patch semantics): the default applies again.
  const JobSpec inlined = loadJob({{"kind", "database"}, {"scene", quickScene()},
                                   {"scene_patch", {{"dem", {{"sample_duration", nullptr}}}}}});
  EXPECT_DOUBLE_EQ(inlined.scene.dem.sample_duration, 10.0);  // the schema's default
  EXPECT_FALSE(json::parse(inlined.scene.source_json)["dem"].contains("sample_duration"));
  EXPECT_DOUBLE_EQ(loadJob({{"kind", "database"}, {"scene", quickScene()}}).scene.dem.sample_duration, 2.0);
  // The quick database job at the issue's length: quick.json with 10 s sampled + 10 s reference.
  const JobSpec tenSeconds = loadJobFile(sourcePath("examples/jobs/quick-database-10s.json"));
  EXPECT_EQ(tenSeconds.scene.name, "quick");
  EXPECT_DOUBLE_EQ(tenSeconds.scene.dem.sample_duration, 10.0);
  EXPECT_DOUBLE_EQ(tenSeconds.scene.dem.reference_duration, 10.0);
}

TEST(Jobs, ScenePatchThatBreaksTheSceneIsRefusedWithItsPointer) {
  using V = std::vector<std::string>;
  const json badValue = {{"dem", {{"sample_duration", -1.0}}}};
  EXPECT_EQ(refusedPointers({{"kind", "database"}, {"scene", quickScene()}, {"scene_patch", badValue}}),
            V{"/scene/dem/sample_duration"});
  try {
    loadJob({{"kind", "database"}, {"scene_file", "../quick.json"}, {"scene_patch", badValue}}, "job",
            sourcePath("examples/jobs"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u) << e.what();
    EXPECT_EQ(e.violations()[0].pointer, "/dem/sample_duration");  // in the scene file, as without a patch
    EXPECT_NE(std::string(e.what()).find("scene_patch"), std::string::npos) << e.what();
  }
  // The patch itself must be an object.
  EXPECT_EQ(refusedPointers({{"kind", "database"}, {"scene", quickScene()}, {"scene_patch", 3}}), V{"/scene_patch"});
}

TEST(Jobs, ADatabaseJobWhoseBedCannotFitTheChamberIsRefusedBeforeItStarts) {
  // The quick slice is filled from its region 0.2 m < y < 0.3 m: below it the chamber holds 5.42e-4 m3,
  // at most 0.28 kg of its particles poured at alpha_P 0.5 (the bed is 0.15 kg).
  json scene = quickScene();
  scene["process"]["bed_mass"] = 1e12;
  try {
    loadJob({{"kind", "database"}, {"scene", scene}}, "job");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u) << e.what();
    EXPECT_EQ(e.violations()[0].pointer, "/scene/process/bed_mass");
    EXPECT_NE(e.violations()[0].message.find("at most 0.28"), std::string::npos) << e.what();
  }
  scene["process"]["bed_mass"] = 0.27;  // fits, poured
  EXPECT_NO_THROW(loadJob({{"kind", "database"}, {"scene", scene}}, "job"));
  scene["process"]["bed_mass"] = 0.29;
  EXPECT_THROW(loadJob({{"kind", "database"}, {"scene", scene}}, "job"), InputError);
  // Only the CFD-DEM fills the bed: a spray job on such a scene counts particles, nothing more.
  scene["process"]["bed_mass"] = 1e12;
  EXPECT_NO_THROW(loadJob({{"kind", "spray"}, {"scene", scene}, {"database", "db.h5"}, {"duration", 1.0}}, "job"));
}

TEST(Jobs, ADatabaseJobWhoseFramesMissTheDemStepsIsRefusedBeforeItStarts) {
  // 0.0123 s at 200 Hz is 2.46 frames: the database job's schedule (DatabaseSchedule) refuses it when
  // it starts, and loading the job (what the server does at submit) refuses it the same way.
  json scene = quickScene();
  scene["dem"]["sample_duration"] = 0.0123;
  try {
    loadJob({{"kind", "database"}, {"scene", scene}}, "job");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u) << e.what();
    EXPECT_EQ(e.violations()[0].pointer, "/scene/dem/sample_duration");
    EXPECT_NE(e.violations()[0].message.find("whole number"), std::string::npos) << e.what();
  }
  scene["dem"]["sample_duration"] = 0.015;  // 3 frames
  EXPECT_NO_THROW(loadJob({{"kind", "database"}, {"scene", scene}}, "job"));
  scene["dem"]["sample_rate"] = 300.0;  // 133.3 DEM steps of 25 us per frame
  try {
    loadJob({{"kind", "database"}, {"scene", scene}}, "job");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.violations().at(0).pointer, "/scene/dem/sample_rate") << e.what();
  }
}

TEST(Jobs, CalibrationAndSprayRulesOfTheJobsAreCheckedWhenTheJobIsLoaded) {
  // What the jobs check at start (requireJobRules), loadJob checks too, so the server refuses it at submit.
  const json scene = quickScene();  // rcfd.dt = 5 ms
  auto pointersOf = [](const json& job) {
    std::vector<std::string> out;
    try {
      loadJob(job, "job");
    } catch (const InputError& e) {
      for (const auto& v : e.violations()) out.push_back(v.pointer);
    }
    return out;
  };
  using V = std::vector<std::string>;
  const json calibration = {{"kind", "calibration"}, {"scene", scene}, {"database", "db.h5"}, {"duration", 2.0}};
  json job = calibration;
  job["discard"] = 2.0;
  EXPECT_EQ(pointersOf(job), V{"/discard"});
  job["discard"] = 0.5;
  EXPECT_EQ(pointersOf(job), V{});
  job["d0_values"] = {0.0, 1e-3, 1e-3};
  EXPECT_EQ(pointersOf(job), V{"/d0_values/2"});
  job = calibration;
  job["discard"] = 0.5;
  job["scene"]["probes"] = json::array();
  EXPECT_EQ(pointersOf(job), V{"/scene/probes"});
  EXPECT_EQ(pointersOf({{"kind", "spray"}, {"scene", scene}, {"database", "db.h5"}, {"duration", 0.001}}),
            V{"/duration"});
  // The same rules on a spec built in code, as the jobs apply them.
  JobSpec spec = loadJob({{"kind", "spray"}, {"scene", scene}, {"database", "db.h5"}, {"duration", 1.0}}, "job");
  spec.duration = 0.001;
  EXPECT_THROW(requireJobRules(spec), InputError);
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
    const std::string pointer = "/scene/effects/" + std::to_string(scene["effects"].size() - 1);
    EXPECT_NE(text.find(pointer + ": unknown effect \"bogus\""), std::string::npos) << text;
  }
}
