// The job schema's "calibration" object: accepted keys, ranges, and only for calibration jobs.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/Errors.hpp"
#include "scene/SceneLoader.hpp"

using namespace rcfd;
using nlohmann::json;

namespace {

json calibrationJob(const json& options) {
  std::ifstream in(std::string(RCFD_SOURCE_DIR) + "/examples/quick.json");
  json job = {{"kind", "calibration"}, {"scene", json::parse(in)}, {"database", "db.h5"}, {"duration", 35.0}};
  if (!options.is_null()) job["calibration"] = options;
  return job;
}

std::vector<std::string> refusedPointers(const json& job) {
  try {
    loadJob(job, "job");
  } catch (const InputError& e) {
    std::vector<std::string> pointers;
    for (const auto& v : e.violations()) pointers.push_back(v.pointer);
    return pointers;
  }
  ADD_FAILURE() << "job accepted";
  return {};
}

bool mentions(const std::vector<std::string>& pointers, const std::string& p) {
  return std::find(pointers.begin(), pointers.end(), p) != pointers.end();
}

}  // namespace

TEST(CalibrationJobOptions, AcceptedKeys) {
  const JobSpec job = loadJob(calibrationJob({{"field_rms_tolerance", 0.3}, {"ks_threshold", 0.2},
                                              {"rtd_relative_tolerance", 0.05}, {"parallel", "tracers"}}));
  EXPECT_EQ(job.source["calibration"]["ks_threshold"], 0.2);
  EXPECT_NO_THROW(loadJob(calibrationJob(json())));
  EXPECT_NO_THROW(loadJob(calibrationJob(json::object())));
}

TEST(CalibrationJobOptions, RefusedValuesNameTheKey) {
  EXPECT_TRUE(mentions(refusedPointers(calibrationJob({{"ks_threshold", 0.0}})), "/calibration/ks_threshold"));
  EXPECT_TRUE(mentions(refusedPointers(calibrationJob({{"ks_threshold", 1.2}})), "/calibration/ks_threshold"));
  EXPECT_TRUE(mentions(refusedPointers(calibrationJob({{"field_rms_tolerance", -0.1}})),
                       "/calibration/field_rms_tolerance"));
  EXPECT_TRUE(mentions(refusedPointers(calibrationJob({{"rtd_relative_tolerance", 0}})),
                       "/calibration/rtd_relative_tolerance"));
  EXPECT_TRUE(mentions(refusedPointers(calibrationJob({{"parallel", "gpus"}})), "/calibration/parallel"));
  const auto unknown = refusedPointers(calibrationJob({{"ks", 0.1}}));
  EXPECT_FALSE(unknown.empty());
  EXPECT_TRUE(mentions(unknown, "/calibration") || mentions(unknown, "/calibration/ks"));
}

TEST(CalibrationJobOptions, OnlyCalibrationJobsTakeThem) {
  json job = calibrationJob({{"ks_threshold", 0.2}});
  job["kind"] = "spray";
  EXPECT_TRUE(mentions(refusedPointers(job), "/calibration"));
}
