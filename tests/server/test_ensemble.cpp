// An ensemble spray job through the server and the real solver: the result shows the ensemble block,
// the coverage export carries the members' band (JSON, CSV, HDF5, merged bins too), and result.h5 and
// the band figure download like any artifact.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "ServerFixture.hpp"
#include "SmallDatabase.hpp"

using namespace rcfd::test;

TEST(ServerEnsemble, ResultCoverageBandAndArtifactsOfAnEnsembleJob) {
  if (!std::filesystem::exists(binaryDir() / "rcfd-solve")) GTEST_SKIP() << "build rcfd-solve first";
  TempDir tmp;
  const nlohmann::json scene = withTracers(quickScene(), 200);
  writeSmallDatabase(scene, tmp.path() / "db.h5");
  ServerProcess server(tmp.path() / "data", "ensemble-token",
                       {"--workers", "1", "--solver", (binaryDir() / "rcfd-solve").string(), "--worker-nice", "0"});
  std::ifstream file(tmp.path() / "db.h5", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(file)), {});
  const Reply uploaded = server.post("/v1/databases", bytes, {{"Content-Type", "application/x-hdf5"}});
  ASSERT_EQ(uploaded.status, 201) << uploaded.body;
  const nlohmann::json job = {{"kind", "spray"},   {"scene", scene},       {"database", uploaded.json().at("id")},
                              {"duration", 0.25}, {"seed", 3},            {"checkpoint_interval", 0.05},
                              {"ensemble", {{"members", 3}}}};
  const Reply submitted = server.post("/v1/jobs", job.dump());
  ASSERT_EQ(submitted.status, 202) << submitted.body;
  const std::string id = submitted.json().at("id");
  nlohmann::json state;
  for (int i = 0; i < 1200; ++i) {
    state = server.get("/v1/jobs/" + id).json();
    const std::string s = state.at("state");
    if (s == "SUCCEEDED" || s == "FAILED" || s == "CANCELLED") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_EQ(state.at("state"), "SUCCEEDED") << state.dump(2) << server.stderrText();

  const nlohmann::json result = server.get("/v1/jobs/" + id + "/result").json();
  ASSERT_TRUE(result.contains("ensemble")) << result.dump(1);
  EXPECT_EQ(result["ensemble"]["members"], 3);
  EXPECT_EQ(result["ensemble"]["seeds"][0], 3);
  const auto& artifacts = state.at("artifacts");
  for (const char* name : {"result.h5", "summary.json", "coverage.svg"}) {
    EXPECT_NE(std::find(artifacts.begin(), artifacts.end(), name), artifacts.end()) << name << artifacts.dump();
  }
  const Reply svg = server.get("/v1/jobs/" + id + "/artifacts/coverage.svg");
  EXPECT_EQ(svg.status, 200);
  EXPECT_NE(svg.body.find("3 members"), std::string::npos);

  // The coverage export: member 0's counts, as without an ensemble, and the band of the members.
  const nlohmann::json& histogram = result["ensemble"]["coverage"]["histogram"];
  const nlohmann::json json = server.get("/v1/jobs/" + id + "/coverage?format=json").json();
  EXPECT_EQ(json.at("counts"), result["coverage"]["histogram"]["counts"]);
  ASSERT_TRUE(json.contains("ensemble")) << json.dump(1);
  EXPECT_EQ(json["ensemble"]["members"], 3);
  EXPECT_EQ(json["ensemble"]["mean"], histogram["mean"]);
  EXPECT_EQ(json["ensemble"]["ci95_high"], histogram["ci95_high"]);
  const std::size_t bins = histogram["mean"].size();
  if (bins % 2 == 0) {  // merged bins: the members' counts merged, then their spread
    const nlohmann::json merged =
        server.get("/v1/jobs/" + id + "/coverage?format=json&bins=" + std::to_string(bins / 2)).json();
    for (std::size_t b = 0; b < bins / 2; ++b) {
      EXPECT_NEAR(merged["ensemble"]["mean"][b].get<double>(),
                  histogram["mean"][2 * b].get<double>() + histogram["mean"][2 * b + 1].get<double>(), 1e-9);
    }
  }
  const Reply csv = server.get("/v1/jobs/" + id + "/coverage?format=csv");
  std::istringstream lines(csv.body);
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header, "lower,upper,count,members,mean,sd,sem,ci95_low,ci95_high,min,max");
  const Reply h5 = server.get("/v1/jobs/" + id + "/coverage?format=h5");
  ASSERT_EQ(h5.status, 200);
  std::ofstream(tmp.path() / "coverage.h5", std::ios::binary) << h5.body;
  const Reply r = server.get("/v1/jobs/" + id + "/artifacts/result.h5");
  ASSERT_EQ(r.status, 200);
  std::ofstream(tmp.path() / "result.h5", std::ios::binary) << r.body;
  for (const auto& [name, set] : {std::pair{"coverage.h5", "/ensemble/mean"}, std::pair{"result.h5", "/ensemble/seeds"},
                                  std::pair{"result.h5", "/ensemble/members/02/coverage/per_tracer"}}) {
    const hid_t f = H5Fopen((tmp.path() / name).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0) << name;
    EXPECT_GT(H5Lexists(f, "/ensemble", H5P_DEFAULT), 0) << name;
    const hid_t d = H5Dopen2(f, set, H5P_DEFAULT);
    EXPECT_GE(d, 0) << name << set;
    if (d >= 0) H5Dclose(d);
    H5Fclose(f);
  }
}
