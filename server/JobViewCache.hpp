#pragma once
/// \file JobViewCache.hpp
/// Rendered bodies of GET /v1/jobs/{id}, kept until the job's row changes. Polling clients ask for
/// the same job far more often than its row changes (the worker writes progress at most every
/// 250 ms), so most polls are answered without SQLite or JSON work. JobStore's change listener
/// invalidates an entry after each committed write; a body rendered from a row read before that
/// write is never stored (generations), so the cache never serves a stale job.

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace rcfd::server {

class JobViewCache {
 public:
  explicit JobViewCache(std::size_t capacity = kDefaultCapacity) : capacity_(capacity) {}

  /// The cached body of job `id`, or null.
  std::shared_ptr<const std::string> find(const std::string& id);
  /// Take this before reading the row a body is rendered from, and give it to store().
  std::uint64_t generation();
  /// Keeps `body` unless some job changed since `generation` was taken (then the row may be old).
  void store(const std::string& id, std::shared_ptr<const std::string> body, std::uint64_t generation);
  /// The job's row changed: forget its body.
  void invalidate(const std::string& id);

  static constexpr std::size_t kDefaultCapacity = 4096;

 private:
  std::mutex mutex_;
  std::unordered_map<std::string, std::shared_ptr<const std::string>> bodies_;
  std::uint64_t generation_ = 0;
  std::size_t capacity_;
};

}  // namespace rcfd::server
