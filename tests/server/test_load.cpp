// Load: 200 concurrent keep-alive connections polling GET /v1/jobs/{id} for 5 s on loopback (the
// 30 s version is `rcfd-bench server`). No request may fail; p50/p99 are printed.

#include <gtest/gtest.h>

#include "LoadGenerator.hpp"
#include "ServerFixture.hpp"

using namespace rcfd::test;

TEST(Load, TwoHundredClientsPollStatusWithoutErrors) {
  TempDir tmp;
  ServerProcess server(tmp.path() / "data", "load-token");
  const std::string id = server.post("/v1/jobs", databaseJob().dump()).json().at("id");
  const auto result = runStatusLoad(server.port(), "load-token", "/v1/jobs/" + id, 200,
                                    std::chrono::seconds(5), 2);
  std::printf("load: %llu requests in %.1f s (%.0f req/s), p50 %.3f ms, p99 %.3f ms, errors %llu\n",
              static_cast<unsigned long long>(result.requests), result.seconds,
              result.requests / result.seconds, result.p50Ms, result.p99Ms,
              static_cast<unsigned long long>(result.errors));
  EXPECT_EQ(result.errors, 0u);
  EXPECT_GT(result.requests, 1000u);
  EXPECT_EQ(server.get("/v1/health").status, 200);
}
