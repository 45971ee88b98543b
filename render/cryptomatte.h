// Cryptomatte (Friedman & Jones 2015; the Cryptomatte specification 1.1.0,
// Psyop): ID mattes that compositors (Nuke, Blender, Natron) decode by name.
// Each name is hashed with MurmurHash3_x86_32 (seed 0) and the hash's bits
// become a float32 ID (its exponent clamped to [1, 254], so no NaN, infinity
// or denormal); per pixel the IDs seen are ranked by coverage and written as
// (ID, coverage) pairs into layers <type>00, <type>01, ... (R, G: rank 0;
// B, A: rank 1; and so on); the header carries, under
// cryptomatte/<key>/ (key: the first 7 hex digits of the type's own hash),
// its name, "MurmurHash3_32", "uint32_to_float32" and the manifest, a JSON
// object of name: 8 hex digits of the ID's float bits. A sample that sees
// nothing (the sky) counts as ID 0, as the specification says, so the
// coverages of a pixel sum to 1.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace drift::render {

// MurmurHash3_x86_32 (Appleby, public domain) of `bytes` with `seed`.
std::uint32_t murmur3_32(std::string_view bytes, std::uint32_t seed = 0);

// The specification's uint32_to_float32: the hash's bits with the exponent
// clamped to [1, 254].
float cryptomatte_id(std::string_view name);

// The 8 hex digits of an ID's float bits, as the manifest writes them.
std::string cryptomatte_hex(float id);

// One Cryptomatte type (e.g. "CryptoMaterial") and the names it may show.
struct CryptomatteLayer {
  std::string type;
  std::vector<std::string> names;  // distinct
  int ranks = 6;                   // (ID, coverage) pairs per pixel, even

  // "<type>00.R", "<type>00.G", ... : ranks / 2 layers of four channels.
  std::vector<std::string> channels() const;
  // The header attributes: name, hash, conversion, manifest.
  std::vector<std::pair<std::string, std::string>> header() const;
  // The key under cryptomatte/: 7 hex digits of the type's hash.
  std::string key() const;
};

// The ranks a layer of `names` names needs so that no pixel loses coverage:
// every name and the empty ID 0, rounded up to pairs, at most `cap`.
int ranks_for(std::size_t names, int cap = 16);

// Writes the (ID, coverage) pairs of one pixel into out[0 .. ranks * 2):
// `weights[i]` is name i's share, `empty` the share that saw nothing (ID 0);
// ranked by coverage, highest first (ties: in name order), pairs past the
// last nonzero one are (0, 0).
void rank_coverage(const CryptomatteLayer& layer, const std::vector<float>& ids,
                   const float* weights, float empty, float* out);

}  // namespace drift::render
