// Load: 200 concurrent keep-alive clients polling GET /v1/jobs/{id} on loopback for 3 s (then 2 s back to back)
// (the 30 s version, while a spray job runs, is `rcfd-bench server`): polling every 100 ms (2000 requests/s offered), then
// back to back (saturation). No request may fail; p50/p99 are printed for docs/performance.md.

#include <gtest/gtest.h>

#include "LoadGenerator.hpp"
#include "ServerFixture.hpp"

using namespace rcfd::test;

namespace {
void report(const char* what, const LoadResult& r) {
  std::printf("load %s: %llu requests in %.1f s (%.0f req/s), p50 %.3f ms, p99 %.3f ms, max %.3f ms, "
              "errors %llu\n",
              what, static_cast<unsigned long long>(r.requests), r.seconds, r.requests / r.seconds,
              r.p50Ms, r.p99Ms, r.maxMs, static_cast<unsigned long long>(r.errors));
}
}  // namespace

TEST(Load, TwoHundredClientsPollStatusWithoutErrors) {
  TempDir tmp;
  ServerProcess server(tmp.path() / "data", "load-token");
  const std::string id = server.post("/v1/jobs", databaseJob().dump()).json().at("id");
  const std::string target = "/v1/jobs/" + id;

  const auto polling = runStatusLoad(server.port(), "load-token", target, 200, std::chrono::seconds(3),
                                     1, std::chrono::milliseconds(100));
  report("polling every 100 ms", polling);
  EXPECT_EQ(polling.errors, 0u);
  EXPECT_GT(polling.requests, 3000u);  // 200 clients x 10/s x 3 s = 6000 if the server keeps up

  const auto saturated =
      runStatusLoad(server.port(), "load-token", target, 200, std::chrono::seconds(2), 1);
  report("back to back", saturated);
  EXPECT_EQ(saturated.errors, 0u);
  EXPECT_GT(saturated.requests, 1000u);
  EXPECT_EQ(server.get("/v1/health").status, 200);
}
