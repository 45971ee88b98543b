// A least-recently-used cache of float blocks under a byte budget: the
// out-of-core terrain's pages of heights (render/paged_terrain.h), read on
// demand and dropped, oldest use first, when the next would exceed the budget
// (`drift render --memory-budget BYTES`, issue 36 item 2).
//
// The cache changes when a block is read, never what a block holds: a loader
// must return the same values for a key every time, so whatever the cache
// keeps or drops, and whatever the thread interleaving, every ray sees the
// same heights and the image is the same bits. Thread-safe: one mutex over
// the cache's lists; a miss calls the loader outside it (threads missing
// different blocks read them side by side: the loader must be thread-safe),
// and a thread missing a block another thread is reading waits for that read
// (one read a block).
#pragma once

#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

namespace drift::render {

struct BlockCacheStats {
  std::uint64_t hits = 0, misses = 0;
  std::uint64_t bytes_read = 0;     // what the loader returned, in all
  std::uint64_t peak_resident = 0;  // most bytes of blocks held at once
  std::uint64_t resident = 0;       // bytes of blocks held now
};

class BlockCache {
 public:
  using Block = std::vector<float>;
  using Loader = std::function<Block(std::uint64_t key)>;

  // Throws drift::Error if `budget_bytes` cannot hold one block of
  // `max_block_bytes` (the largest block the loader returns), naming both.
  BlockCache(std::uint64_t budget_bytes, std::uint64_t max_block_bytes, Loader loader);

  // The block of `key`, read by the loader on a miss. The returned pointer
  // keeps the block alive while the caller reads it, even if the cache drops
  // it meanwhile (one such block per reading thread may outlive its place in
  // the cache: the budget bounds what the cache holds).
  std::shared_ptr<const Block> get(std::uint64_t key);

  BlockCacheStats stats() const;
  std::uint64_t budget() const { return budget_; }
  // Keys held, most recently used first (for tests).
  std::vector<std::uint64_t> keys() const;

 private:
  struct Entry {
    std::uint64_t key;
    std::shared_ptr<const Block> block;
  };
  std::uint64_t budget_;
  Loader loader_;
  mutable std::mutex mutex_;
  std::list<Entry> lru_;  // front: most recently used
  std::unordered_map<std::uint64_t, std::list<Entry>::iterator> index_;
  // Blocks being read, for threads that miss them meanwhile.
  std::unordered_map<std::uint64_t, std::shared_future<std::shared_ptr<const Block>>> loading_;
  BlockCacheStats stats_;
};

}  // namespace drift::render
