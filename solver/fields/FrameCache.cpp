#include "fields/FrameCache.hpp"

namespace rcfd {

std::shared_ptr<const FieldFrame> FrameCache::get(int index, const Loader& load) {
  {
    std::lock_guard lock(mutex_);
    auto it = entries_.find(index);
    if (it != entries_.end()) {
      ++stats_.hits;
      recency_.splice(recency_.begin(), recency_, it->second.position);
      return it->second.frame;
    }
  }
  std::lock_guard loadLock(loadMutex_);
  {
    // Another thread may have loaded it while this one waited for the load lock.
    std::lock_guard lock(mutex_);
    auto it = entries_.find(index);
    if (it != entries_.end()) {
      ++stats_.hits;
      recency_.splice(recency_.begin(), recency_, it->second.position);
      return it->second.frame;
    }
  }
  std::shared_ptr<const FieldFrame> frame = load(index);
  std::lock_guard lock(mutex_);
  ++stats_.misses;
  recency_.push_front(index);
  entries_.emplace(index, Entry{frame, recency_.begin()});
  stats_.residentBytes += std::int64_t(frame->bytes());
  while (stats_.residentBytes > capacity_ && recency_.size() > 1) {
    const int victim = recency_.back();
    recency_.pop_back();
    auto v = entries_.find(victim);
    stats_.residentBytes -= std::int64_t(v->second.frame->bytes());
    entries_.erase(v);
  }
  return frame;
}

FrameCacheStats FrameCache::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace rcfd
