#pragma once
/// \file Metrics.hpp
/// Request counters and a latency histogram (lock-free), rendered with the job gauges as Prometheus
/// text exposition format 0.0.4 for GET /metrics.

#include <array>
#include <atomic>
#include <cstdint>
#include <string>

namespace rcfd::server {

class JobStore;

class Metrics {
 public:
  /// Upper bounds of the latency buckets [s].
  static constexpr std::array<double, 12> kBuckets = {0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025,
                                                      0.05,   0.1,   0.25,   0.5,   1.0,  2.5};

  /// Records one answered request: handling time [s] and HTTP status.
  void observe(double seconds, int status);
  /// The exposition text: rcfd_jobs{state}, rcfd_queue_length, rcfd_workers_busy,
  /// rcfd_http_requests_total{code}, rcfd_http_request_duration_seconds histogram.
  std::string render(JobStore& store, int workersBusy, int workerSlots) const;

 private:
  std::array<std::atomic<std::uint64_t>, kBuckets.size() + 1> buckets_{};  // last: +Inf
  std::atomic<std::uint64_t> sumMicros_{0};
  std::array<std::atomic<std::uint64_t>, 6> byClass_{};  // 1xx..5xx, index 0 unused
};

}  // namespace rcfd::server
