#pragma once
/// \file FrameCache.hpp
/// A thread-safe least-recently-used cache of frames bounded in bytes. A miss loads the frame through
/// the caller's loader while other threads keep being served from the cache; loads are serialised, so
/// a frame requested by two threads at once is read from disk once and counted as one miss.

#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>

#include "fields/FieldDatabase.hpp"

namespace rcfd {

class FrameCache {
 public:
  using Loader = std::function<std::shared_ptr<const FieldFrame>(int index)>;

  /// At most `capacityBytes` of frames stay resident (the most recently used is always kept).
  explicit FrameCache(std::int64_t capacityBytes) : capacity_(capacityBytes) {}

  /// The frame `index`, from the cache (a hit) or through `load` (a miss, then cached).
  std::shared_ptr<const FieldFrame> get(int index, const Loader& load);
  FrameCacheStats stats() const;
  std::int64_t capacityBytes() const { return capacity_; }

 private:
  struct Entry {
    std::shared_ptr<const FieldFrame> frame;
    std::list<int>::iterator position;  // in recency_, front = most recent
  };
  std::int64_t capacity_;
  mutable std::mutex mutex_;  // guards everything below
  std::mutex loadMutex_;      // serialises disk reads
  std::list<int> recency_;
  std::unordered_map<int, Entry> entries_;
  FrameCacheStats stats_;
};

}  // namespace rcfd
