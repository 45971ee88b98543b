#include "render/cryptomatte.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <numeric>

#include "terrain/json_text.h"

namespace drift::render {

namespace {

std::uint32_t rotl32(std::uint32_t x, int r) { return (x << r) | (x >> (32 - r)); }

std::uint32_t fmix32(std::uint32_t h) {
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  return h;
}

// A JSON string literal of `s` (names are letters, digits, '_' and '-', but
// object names come from files: escape what JSON requires).

}  // namespace

std::uint32_t murmur3_32(std::string_view bytes, std::uint32_t seed) {
  constexpr std::uint32_t c1 = 0xcc9e2d51u, c2 = 0x1b873593u;
  const std::size_t n = bytes.size();
  std::uint32_t h = seed;
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    std::uint32_t k = 0;
    std::memcpy(&k, bytes.data() + i, 4);  // little-endian blocks, as x86
    k *= c1;
    k = rotl32(k, 15);
    k *= c2;
    h ^= k;
    h = rotl32(h, 13);
    h = h * 5 + 0xe6546b64u;
  }
  std::uint32_t k = 0;
  switch (n & 3) {
    case 3:
      k ^= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 2])) << 16;
      [[fallthrough]];
    case 2:
      k ^= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
      [[fallthrough]];
    case 1:
      k ^= static_cast<unsigned char>(bytes[i]);
      k *= c1;
      k = rotl32(k, 15);
      k *= c2;
      h ^= k;
      break;
    default:
      break;
  }
  h ^= static_cast<std::uint32_t>(n);
  return fmix32(h);
}

float cryptomatte_id(std::string_view name) {
  const std::uint32_t hash = murmur3_32(name);
  const std::uint32_t mantissa = hash & ((1u << 23) - 1);
  const std::uint32_t exponent = std::clamp((hash >> 23) & 0xffu, 1u, 254u);
  const std::uint32_t bits = (hash & 0x80000000u) | (exponent << 23) | mantissa;
  float id;
  std::memcpy(&id, &bits, 4);
  return id;
}

std::string cryptomatte_hex(float id) {
  std::uint32_t bits;
  std::memcpy(&bits, &id, 4);
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08x", bits);
  return hex;
}

std::vector<std::string> CryptomatteLayer::channels() const {
  std::vector<std::string> out;
  for (int layer = 0; layer < ranks / 2; ++layer) {
    char index[16];
    std::snprintf(index, sizeof index, "%02d", layer);
    for (const char* c : {".R", ".G", ".B", ".A"}) out.push_back(type + index + c);
  }
  return out;
}

std::string CryptomatteLayer::key() const {
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08x", murmur3_32(type));
  return std::string(hex, 7);
}

std::vector<std::pair<std::string, std::string>> CryptomatteLayer::header() const {
  std::string manifest = "{";
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) manifest += ",";
    manifest += terrain::json_string(names[i]) + ":" +
                terrain::json_string(cryptomatte_hex(cryptomatte_id(names[i])));
  }
  manifest += "}";
  const std::string prefix = "cryptomatte/" + key() + "/";
  return {{prefix + "name", type},
          {prefix + "hash", "MurmurHash3_32"},
          {prefix + "conversion", "uint32_to_float32"},
          {prefix + "manifest", manifest}};
}

int ranks_for(std::size_t names, int cap) {
  const int wanted =
      static_cast<int>(std::min<std::size_t>(names + 1, static_cast<std::size_t>(cap)));
  return std::max(2, (wanted + 1) / 2 * 2);
}

void rank_coverage(const CryptomatteLayer& layer, const std::vector<float>& ids,
                   const float* weights, float empty, float* out) {
  const std::size_t n = layer.names.size();
  // Candidates: every name, then the empty ID (index n).
  thread_local std::vector<int> order;
  const std::size_t count = n + 1;
  order.resize(count);
  std::iota(order.begin(), order.end(), 0);
  auto weight = [&](int i) { return static_cast<std::size_t>(i) == n ? empty : weights[i]; };
  const auto heavier = [&](int a, int b) { return weight(a) > weight(b); };
  // A pixel's few names (coverage channels, objects): a stable insertion
  // sort, the same order as std::stable_sort's without its buffer, which it
  // allocated for every pixel (2 % of a 4-spp frame's time).
  constexpr std::size_t kInsertionSortUpTo = 32;
  if (count <= kInsertionSortUpTo) {
    for (std::size_t i = 1; i < count; ++i) {
      const int key = order[i];
      std::size_t j = i;
      for (; j > 0 && heavier(key, order[j - 1]); --j) order[j] = order[j - 1];
      order[j] = key;
    }
  } else {
    std::stable_sort(order.begin(), order.end(), heavier);
  }
  for (int r = 0; r < layer.ranks; ++r) {
    float id = 0.0f, coverage = 0.0f;
    if (static_cast<std::size_t>(r) < count && weight(order[static_cast<std::size_t>(r)]) > 0.0f) {
      const int i = order[static_cast<std::size_t>(r)];
      id = static_cast<std::size_t>(i) == n ? 0.0f : ids[static_cast<std::size_t>(i)];
      coverage = weight(i);
    }
    out[2 * r] = id;
    out[2 * r + 1] = coverage;
  }
}

}  // namespace drift::render
