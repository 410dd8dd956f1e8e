#pragma once
/// \file JobViewCache.hpp
/// Rendered bodies of GET /v1/jobs/{id}, kept until the job's row changes. Polling clients ask for
/// the same job far more often than its row changes (the worker writes progress at most every
/// 250 ms), so most polls are answered without SQLite or JSON work. JobStore's change listener
/// invalidates an entry after each committed write; a body rendered from a row read before that
/// write is never stored (generations), so the cache never serves a stale job. Each body keeps its
/// job's owner, so a poll answered from the cache is checked against the caller like one read from
/// the store.

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace rcfd::server {

class JobViewCache {
 public:
  struct View {
    std::string owner;  ///< the job's owner: who besides admins may see the body
    std::string body;   ///< GET /v1/jobs/{id} as sent
  };

  explicit JobViewCache(std::size_t capacity = kDefaultCapacity) : capacity_(capacity) {}

  /// The cached view of job `id`, or null.
  std::shared_ptr<const View> find(const std::string& id);
  /// Take this before reading the row a body is rendered from, and give it to store().
  std::uint64_t generation();
  /// Keeps `body` unless some job changed since `generation` was taken (then the row may be old).
  void store(const std::string& id, std::shared_ptr<const View> view, std::uint64_t generation);
  /// The job's row changed: forget its body.
  void invalidate(const std::string& id);

  static constexpr std::size_t kDefaultCapacity = 4096;

 private:
  std::mutex mutex_;
  std::unordered_map<std::string, std::shared_ptr<const View>> bodies_;
  std::uint64_t generation_ = 0;
  std::size_t capacity_;
};

}  // namespace rcfd::server
