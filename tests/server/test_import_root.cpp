// Import jobs read an OpenFOAM case by name, so the server takes them only inside the import root its
// operator named (--import-root): without one, outside it, through `..`, an absolute path or a symbolic
// link that leaves it, the job is refused at submit with the pointer /case_dir.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "ServerFixture.hpp"

using namespace rcfd::test;

namespace {
nlohmann::json importJob(const std::string& caseDir) {
  return {{"kind", "import"}, {"scene", quickScene()}, {"case_dir", caseDir}};
}

void expectRefusedAtCaseDir(const Reply& r, const std::string& detailPart) {
  EXPECT_EQ(r.status, 422) << r.body;
  const auto errors = r.json().at("errors");
  ASSERT_FALSE(errors.empty()) << r.body;
  EXPECT_EQ(errors.at(0).at("pointer"), "/case_dir") << r.body;
  EXPECT_NE(r.body.find(detailPart), std::string::npos) << r.body;
}
}  // namespace

TEST(ImportRoot, WithoutAnImportRootTheServerRefusesImportJobs) {
  TempDir tmp;
  ServerProcess server(tmp.path() / "data", "test-token");
  expectRefusedAtCaseDir(server.post("/v1/jobs", importJob("case").dump()), "--import-root");
}

TEST(ImportRoot, OnlyACaseInsideTheImportRootIsAccepted) {
  namespace fs = std::filesystem;
  TempDir tmp;
  const fs::path root = tmp.path() / "cases", outside = tmp.path() / "elsewhere";
  fs::create_directories(root / "spouted-bed");
  fs::create_directories(outside);
  fs::create_directory_symlink(outside, root / "link-out");
  ServerProcess server(tmp.path() / "data", "test-token", {"--workers", "0", "--import-root", root.string()});
  const std::vector<std::string> leaving = {"../elsewhere", "spouted-bed/../../elsewhere", outside.string(),
                                            "link-out", "/etc"};
  for (const std::string& caseDir : leaving) {
    SCOPED_TRACE(caseDir);
    expectRefusedAtCaseDir(server.post("/v1/jobs", importJob(caseDir).dump()), "inside the server's import root");
  }
  const Reply accepted = server.post("/v1/jobs", importJob("spouted-bed").dump());
  EXPECT_EQ(accepted.status, 202) << accepted.body;
  EXPECT_EQ(accepted.json().at("kind"), "import") << accepted.body;
}
