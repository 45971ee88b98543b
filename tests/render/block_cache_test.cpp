// The out-of-core terrain's LRU cache (render/block_cache.h): least recently
// used dropped first, the budget never exceeded, hits and misses counted,
// and a budget below one block refused.
#include "render/block_cache.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "terrain/error.h"

using drift::render::BlockCache;

namespace {

// Block `key` holds (key % 5 + 1) * 16 floats, each equal to the key.
BlockCache::Block block_of(std::uint64_t key) {
  return BlockCache::Block((key % 5 + 1) * 16, static_cast<float>(key));
}
constexpr std::uint64_t kLargest = 5 * 16 * sizeof(float);

}  // namespace

TEST(BlockCache, DropsTheLeastRecentlyUsedFirst) {
  int loads = 0;
  // Blocks of 64 B (keys 0, 5, 10, ...): a budget of 192 B holds three.
  BlockCache cache(192, 64, [&](std::uint64_t key) {
    ++loads;
    return BlockCache::Block(16, static_cast<float>(key));
  });
  cache.get(1);
  cache.get(2);
  cache.get(3);
  EXPECT_EQ(cache.keys(), (std::vector<std::uint64_t>{3, 2, 1}));
  EXPECT_EQ(cache.get(1)->front(), 1.0f);  // a hit: 1 becomes the most recent
  EXPECT_EQ(cache.keys(), (std::vector<std::uint64_t>{1, 3, 2}));
  cache.get(4);  // drops 2, the least recently used, not 1
  EXPECT_EQ(cache.keys(), (std::vector<std::uint64_t>{4, 1, 3}));
  cache.get(2);  // read again, dropping 3
  EXPECT_EQ(cache.keys(), (std::vector<std::uint64_t>{2, 4, 1}));
  EXPECT_EQ(loads, 5);
  const auto s = cache.stats();
  EXPECT_EQ(s.hits, 1u);
  EXPECT_EQ(s.misses, 5u);
  EXPECT_EQ(s.bytes_read, 5u * 64);
  EXPECT_EQ(s.resident, 192u);
  EXPECT_EQ(s.peak_resident, 192u);
}

TEST(BlockCache, NeverHoldsMoreThanItsBudgetAndCountsEveryGet) {
  for (std::uint64_t budget : {kLargest, 3 * kLargest + 17, 40 * kLargest}) {
    std::uint64_t loads = 0, loaded_bytes = 0;
    BlockCache cache(budget, kLargest, [&](std::uint64_t key) {
      ++loads;
      BlockCache::Block b = block_of(key);
      loaded_bytes += b.size() * sizeof(float);
      return b;
    });
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> pick(0, 60);
    const int gets = 5000;
    for (int i = 0; i < gets; ++i) {
      const std::uint64_t key = pick(rng);
      const auto block = cache.get(key);
      ASSERT_EQ(*block, block_of(key)) << "key " << key;  // what the loader gives, hit or miss
      const auto s = cache.stats();
      ASSERT_LE(s.resident, budget) << "after get " << i;
      ASSERT_LE(s.peak_resident, budget);
      // What the cache says it holds is what its blocks weigh.
      std::uint64_t held = 0;
      for (std::uint64_t k : cache.keys()) held += block_of(k).size() * sizeof(float);
      ASSERT_EQ(held, s.resident);
    }
    const auto s = cache.stats();
    EXPECT_EQ(s.hits + s.misses, static_cast<std::uint64_t>(gets));
    EXPECT_EQ(s.misses, loads);
    EXPECT_EQ(s.bytes_read, loaded_bytes);
    EXPECT_GT(s.peak_resident, budget / 2);                 // the budget was used, not just kept
    if (budget >= 40 * kLargest) EXPECT_EQ(s.misses, 61u);  // all fit: each read once
  }
}

TEST(BlockCache, RefusesABudgetBelowOneBlock) {
  try {
    BlockCache cache(kLargest - 1, kLargest, block_of);
    FAIL() << "a budget below one block was taken";
  } catch (const drift::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot hold one block"), std::string::npos) << what;
    EXPECT_NE(what.find(std::to_string(kLargest)), std::string::npos) << what;
    EXPECT_NE(what.find("--memory-budget"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(BlockCache(kLargest, kLargest, block_of));
}

// Misses read outside the cache's lock: two threads missing different blocks
// read them side by side (the out-of-core render decodes pages on every
// core), and threads missing one block read it once and all get it.
TEST(BlockCache, ReadsDifferentBlocksSideBySideAndOneBlockOnce) {
  std::atomic<int> inside{0}, most{0}, calls{0};
  BlockCache cache(1 << 20, kLargest, [&](std::uint64_t key) {
    ++calls;
    const int now = ++inside;
    int seen = most.load();
    while (now > seen && !most.compare_exchange_weak(seen, now)) {
    }
    // Wait (2 s at most) for the other thread's read to start, and a while
    // for threads asking for this block.
    for (int i = 0; i < 200 && most.load() < 2; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    --inside;
    return block_of(key);
  });
  {
    std::thread a([&] { cache.get(1); });
    std::thread b([&] { cache.get(2); });
    a.join();
    b.join();
  }
  EXPECT_EQ(most.load(), 2) << "the two misses were read one after the other";
  calls = 0;
  std::vector<std::thread> threads;
  std::atomic<int> right{0};
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] { right += cache.get(7)->front() == 7.0f ? 1 : 0; });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(calls.load(), 1);
  EXPECT_EQ(right.load(), 4);
  EXPECT_EQ(cache.stats().misses, 3u);
  EXPECT_EQ(cache.stats().hits, 3u);
}
