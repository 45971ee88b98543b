#include "render/block_cache.h"

#include <algorithm>
#include <exception>
#include <future>
#include <string>
#include <utility>

#include "terrain/error.h"
#include "terrain/memory.h"

namespace drift::render {

BlockCache::BlockCache(std::uint64_t budget_bytes, std::uint64_t max_block_bytes, Loader loader)
    : budget_(budget_bytes), loader_(std::move(loader)) {
  if (budget_bytes < max_block_bytes) {
    throw Error("a memory budget of " + std::to_string(budget_bytes) + " B (" +
                human_bytes(budget_bytes) + ") cannot hold one block of the terrain (" +
                std::to_string(max_block_bytes) + " B); give --memory-budget at least " +
                human_bytes(max_block_bytes) + " (a few hundred MB reads far less often)");
  }
}

std::shared_ptr<const BlockCache::Block> BlockCache::get(std::uint64_t key) {
  // A miss reads outside the lock, so that threads missing different blocks
  // decode them side by side; a thread missing a block another is reading
  // waits for that read (counted as a hit: the block is read once).
  std::promise<std::shared_ptr<const Block>> promise;
  std::unique_lock lock(mutex_);
  if (const auto found = index_.find(key); found != index_.end()) {
    ++stats_.hits;
    lru_.splice(lru_.begin(), lru_, found->second);  // now the most recent
    return found->second->block;
  }
  if (const auto pending = loading_.find(key); pending != loading_.end()) {
    ++stats_.hits;
    const std::shared_future<std::shared_ptr<const Block>> wait = pending->second;
    lock.unlock();
    return wait.get();  // rethrows the reader's error
  }
  ++stats_.misses;
  loading_.emplace(key, promise.get_future().share());
  lock.unlock();
  std::shared_ptr<const Block> block;
  try {
    block = std::make_shared<const Block>(loader_(key));
  } catch (...) {
    std::lock_guard lock(mutex_);
    loading_.erase(key);
    promise.set_exception(std::current_exception());
    throw;
  }
  const std::uint64_t bytes = block->size() * sizeof(float);
  {
    std::lock_guard lock(mutex_);
    loading_.erase(key);
    stats_.bytes_read += bytes;
    // Drop the least recently used until the new block fits the budget (the
    // constructor made sure one block always does).
    while (!lru_.empty() && stats_.resident + bytes > budget_) {
      stats_.resident -= lru_.back().block->size() * sizeof(float);
      index_.erase(lru_.back().key);
      lru_.pop_back();
    }
    if (stats_.resident + bytes > budget_) {
      const Error too_large("a block of " + std::to_string(bytes) +
                            " B exceeds the memory budget of " + std::to_string(budget_) + " B");
      promise.set_exception(std::make_exception_ptr(too_large));
      throw too_large;
    }
    lru_.push_front({key, block});
    index_[key] = lru_.begin();
    stats_.resident += bytes;
    stats_.peak_resident = std::max(stats_.peak_resident, stats_.resident);
  }
  promise.set_value(block);
  return block;
}

BlockCacheStats BlockCache::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

std::vector<std::uint64_t> BlockCache::keys() const {
  std::lock_guard lock(mutex_);
  std::vector<std::uint64_t> out;
  for (const Entry& e : lru_) out.push_back(e.key);
  return out;
}

}  // namespace drift::render
