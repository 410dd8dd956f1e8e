#include "Metrics.hpp"

#include <sstream>

#include "JobStore.hpp"

namespace rcfd::server {

void Metrics::observe(double seconds, int status) {
  std::size_t i = 0;
  while (i < kBuckets.size() && seconds > kBuckets[i]) ++i;
  buckets_[i].fetch_add(1, std::memory_order_relaxed);
  sumMicros_.fetch_add(static_cast<std::uint64_t>(seconds * 1e6), std::memory_order_relaxed);
  const int cls = status / 100;
  if (cls >= 1 && cls <= 5) byClass_[static_cast<std::size_t>(cls)].fetch_add(1);
}

std::string Metrics::render(JobStore& store, int workersBusy, int workerSlots) const {
  std::ostringstream out;
  const auto counts = store.countByState();
  out << "# HELP rcfd_jobs Jobs in the store by state.\n# TYPE rcfd_jobs gauge\n";
  std::int64_t queued = 0;
  for (const auto& [name, n] : counts) {
    out << "rcfd_jobs{state=\"" << name << "\"} " << n << "\n";
    if (name == state::queued) queued = n;
  }
  out << "# HELP rcfd_queue_length Jobs waiting for a worker.\n# TYPE rcfd_queue_length gauge\n"
      << "rcfd_queue_length " << queued << "\n";
  out << "# HELP rcfd_workers_busy Solver processes running.\n# TYPE rcfd_workers_busy gauge\n"
      << "rcfd_workers_busy " << workersBusy << "\n";
  out << "# HELP rcfd_worker_slots Configured worker slots.\n# TYPE rcfd_worker_slots gauge\n"
      << "rcfd_worker_slots " << workerSlots << "\n";
  out << "# HELP rcfd_http_requests_total Answered HTTP requests by status class.\n"
      << "# TYPE rcfd_http_requests_total counter\n";
  for (int c = 1; c <= 5; ++c)
    out << "rcfd_http_requests_total{code=\"" << c << "xx\"} "
        << byClass_[static_cast<std::size_t>(c)].load() << "\n";
  out << "# HELP rcfd_http_request_duration_seconds Time from a complete request to its response.\n"
      << "# TYPE rcfd_http_request_duration_seconds histogram\n";
  std::uint64_t cumulative = 0;
  for (std::size_t i = 0; i < kBuckets.size(); ++i) {
    cumulative += buckets_[i].load();
    out << "rcfd_http_request_duration_seconds_bucket{le=\"" << kBuckets[i] << "\"} " << cumulative
        << "\n";
  }
  cumulative += buckets_.back().load();
  out << "rcfd_http_request_duration_seconds_bucket{le=\"+Inf\"} " << cumulative << "\n";
  out << "rcfd_http_request_duration_seconds_sum " << static_cast<double>(sumMicros_.load()) * 1e-6
      << "\n";
  // The count is the +Inf bucket as read above, so the two are always equal (Prometheus requires it).
  out << "rcfd_http_request_duration_seconds_count " << cumulative << "\n";
  return out.str();
}

}  // namespace rcfd::server
