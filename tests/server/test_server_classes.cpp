// The server's classes called directly (the rcfd_server library), beside the tests through a running
// server: request targets, problem instances, resource ids and the signed page tokens.

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "Ids.hpp"
#include "PageToken.hpp"
#include "Target.hpp"
#include "WorkerPool.hpp"

using namespace rcfd::server;

TEST(ServerTarget, SplitsThePathAndDecodesTheQuery) {
  const auto t = parseTarget("/v1/jobs//abc/?state=QUEUED&name=a+b%2Fc&state=DONE&=ignored");
  ASSERT_TRUE(t);
  EXPECT_EQ(t->path, "/v1/jobs//abc/");
  EXPECT_EQ(t->segments, (std::vector<std::string>{"v1", "jobs", "abc"}));
  EXPECT_EQ(t->query.at("state"), "DONE");  // the last of repeated keys
  EXPECT_EQ(t->query.at("name"), "a b/c");
  EXPECT_EQ(t->query.count(""), 0u);
  EXPECT_FALSE(t->dotSegment);
}

TEST(ServerTarget, RefusesWhatIsNotAnOriginFormAndMarksDotSegments) {
  EXPECT_FALSE(parseTarget(""));
  EXPECT_FALSE(parseTarget("v1/jobs"));
  EXPECT_FALSE(parseTarget("http://host/v1/jobs"));
  EXPECT_FALSE(parseTarget("/v1/jobs?state=%G1"));  // not a hex escape
  EXPECT_FALSE(parseTarget("/v1/jobs?state=%4"));   // truncated escape
  const auto up = parseTarget("/v1/jobs/../databases");
  ASSERT_TRUE(up);
  EXPECT_TRUE(up->dotSegment);
  // Path segments are not decoded: an encoded dot segment is only a name, matched against fixed lists.
  const auto encoded = parseTarget("/v1/jobs/%2e%2e");
  ASSERT_TRUE(encoded);
  EXPECT_FALSE(encoded->dotSegment);
  EXPECT_EQ(encoded->segments.back(), "%2e%2e");
}

TEST(ServerTarget, ProblemInstanceIsThePrintablePathAtMostTwoHundredCharacters) {
  EXPECT_EQ(instancePath("/v1/jobs?token=secret"), "/v1/jobs");
  EXPECT_EQ(instancePath(std::string("/v1/\x01 \xff", 7)), "/v1/%01%20%FF");
  EXPECT_EQ(instancePath(""), "*");
  EXPECT_LE(instancePath("/" + std::string(1000, 'a')).size(), 200u + 2u);
}

TEST(ServerIds, IdsAreDistinctHexAndRecognised) {
  std::set<std::string> seen;
  for (int k = 0; k < 1000; ++k) {
    const std::string id = newId();
    EXPECT_TRUE(isId(id)) << id;
    EXPECT_TRUE(seen.insert(id).second) << id;
  }
  EXPECT_FALSE(isId(std::string(32, 'A')));
  EXPECT_FALSE(isId(std::string(31, 'a')));
  EXPECT_FALSE(isId("../" + std::string(29, 'a')));
}

TEST(ServerIds, Base64UrlRoundTripsEveryByte) {
  std::string all;
  for (int b = 0; b < 256; ++b) all.push_back(char(b));
  for (std::size_t n = 0; n <= all.size(); n += 37) {
    const std::string encoded = base64UrlEncode(all.substr(0, n));
    EXPECT_EQ(encoded.find_first_of("+/="), std::string::npos);
    EXPECT_EQ(base64UrlDecode(encoded), all.substr(0, n)) << n;
  }
  EXPECT_FALSE(base64UrlDecode("a*b"));
}

TEST(ServerPageToken, OnlyTokensTheKeySignedVerify) {
  const auto dir = std::filesystem::temp_directory_path() / ("rcfd-page-token-" + newId());
  std::filesystem::create_directories(dir);
  const std::string key = pageTokenKey(dir);
  EXPECT_EQ(pageTokenKey(dir), key);  // kept in the data directory: the same after a restart
  const nlohmann::json payload = {{"after", "2026-01-01T00:00:00Z"}, {"id", newId()}};
  const std::string token = signPageToken(payload, key);
  EXPECT_EQ(verifyPageToken(token, key), payload);
  std::string altered = token;
  altered[2] = altered[2] == 'A' ? 'B' : 'A';
  EXPECT_FALSE(verifyPageToken(altered, key));
  EXPECT_FALSE(verifyPageToken(token.substr(0, token.size() - 1), key));
  EXPECT_FALSE(verifyPageToken(token, std::string(key.size(), 'k')));
  EXPECT_FALSE(verifyPageToken("", key));
  std::filesystem::remove_all(dir);
}

// Solver children share the cores among the workers unless the server's own environment sets the
// thread count; everything else in it passes through unchanged.
TEST(ServerSolverEnvironment, SharesTheCoresAmongTheWorkersUnlessTheServerSetsTheThreads) {
  const char* plain[] = {"PATH=/usr/bin", "HOME=/var/lib/rcfd", nullptr};
  EXPECT_EQ(solverEnvironment(2, plain, 8),
            (std::vector<std::string>{"PATH=/usr/bin", "HOME=/var/lib/rcfd", "OMP_NUM_THREADS=4"}));
  EXPECT_EQ(solverEnvironment(3, plain, 2)[2], "OMP_NUM_THREADS=1");  // at least one thread each
  EXPECT_EQ(solverEnvironment(0, plain, 2)[2], "OMP_NUM_THREADS=2");  // no workers: no division by 0
  const char* set[] = {"OMP_NUM_THREADS=6", "OMP_WAIT_POLICY=passive", nullptr};
  EXPECT_EQ(solverEnvironment(2, set, 8), (std::vector<std::string>{"OMP_NUM_THREADS=6", "OMP_WAIT_POLICY=passive"}));
}
