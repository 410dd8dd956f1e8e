#include "JobViewCache.hpp"

namespace rcfd::server {

std::shared_ptr<const JobViewCache::View> JobViewCache::find(const std::string& id) {
  std::lock_guard lock(mutex_);
  const auto it = bodies_.find(id);
  return it == bodies_.end() ? nullptr : it->second;
}

std::uint64_t JobViewCache::generation() {
  std::lock_guard lock(mutex_);
  return generation_;
}

void JobViewCache::store(const std::string& id, std::shared_ptr<const View> view,
                         std::uint64_t generation) {
  std::lock_guard lock(mutex_);
  if (generation != generation_) return;
  // Bounded: past the capacity start afresh (the polled jobs come back within one poll interval).
  if (bodies_.size() >= capacity_) bodies_.clear();
  bodies_[id] = std::move(view);
}

void JobViewCache::invalidate(const std::string& id) {
  std::lock_guard lock(mutex_);
  ++generation_;
  bodies_.erase(id);
}

}  // namespace rcfd::server
