// Owen-scrambled Sobol points (Sobol 1967; Owen 1995) with hash-based
// scrambling and shuffling after Burley 2020, "Practical Hash-based Owen
// Scrambling" (JCGT 9(4)): a 4-D Sobol sequence whose sample index is
// Owen-scrambled (a random shuffle that keeps every power-of-two prefix a
// (0,m,2)-net in dimensions 0 and 1) and whose every coordinate is
// Owen-scrambled with a seed of its own. render/random.h draws from it.
#pragma once

#include <array>
#include <cstdint>

namespace drift::render::sobol {

// Dimensions tabulated: enough for Burley's padding, which takes each set of
// up to four dimensions from a 4-D Sobol sequence of its own.
inline constexpr int kDimensions = 4;

// The generator matrix of one Sobol dimension as 32 columns (column k is the
// direction number v_{k+1} = m_{k+1} / 2^{k+1} in 32-bit fixed point), from
// the primitive polynomial of degree s with middle coefficients `a` and the
// initial m_1 .. m_s by Sobol's recurrence (Joe & Kuo 2008, eq. (2.2)):
// m_k = 2 a_1 m_{k-1} ^ 4 a_2 m_{k-2} ^ ... ^ 2^s m_{k-s} ^ m_{k-s}.
constexpr std::array<std::uint32_t, 32> joe_kuo_matrix(int s, std::uint32_t a,
                                                       std::array<std::uint32_t, 3> m_init) {
  std::array<std::uint32_t, 33> m{};  // m[1..32]
  for (int k = 1; k <= s; ++k) m[k] = m_init[k - 1];
  for (int k = s + 1; k <= 32; ++k) {
    m[k] = m[k - s] ^ (m[k - s] << s);
    for (int j = 1; j < s; ++j) {
      if ((a >> (s - 1 - j)) & 1u) m[k] ^= m[k - j] << j;
    }
  }
  std::array<std::uint32_t, 32> v{};
  for (int k = 1; k <= 32; ++k) v[k - 1] = m[k] << (32 - k);
  return v;
}

// The first dimension: the van der Corput sequence (all m_k = 1, the
// identity matrix read from the top bit down).
constexpr std::array<std::uint32_t, 32> van_der_corput_matrix() {
  std::array<std::uint32_t, 32> v{};
  for (int k = 0; k < 32; ++k) v[k] = 1u << (31 - k);
  return v;
}

// The first four dimensions of Joe & Kuo's table new-joe-kuo-6.21201: van
// der Corput, then its d = 2 (s 1, a 0, m 1), d = 3 (s 2, a 1, m 1 3) and
// d = 4 (s 3, a 1, m 1 3 1).
inline constexpr std::array<std::array<std::uint32_t, 32>, kDimensions> kMatrices = {
    van_der_corput_matrix(), joe_kuo_matrix(1, 0, {1, 0, 0}), joe_kuo_matrix(2, 1, {1, 3, 0}),
    joe_kuo_matrix(3, 1, {1, 3, 1})};

inline std::uint32_t reverse_bits(std::uint32_t x) {
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
  return x;
}

// A generator matrix applied a byte at a time: entry [b][v] is the XOR of
// the columns 8b .. 8b + 7 selected by the bits of v. Four lookups replace
// the loop over the index's bits, which a shuffled index (random in every
// bit) made 32 steps long: 2.7 % of the default frame's time went there.
using ByteTables = std::array<std::array<std::uint32_t, 256>, 4>;

constexpr ByteTables byte_tables(const std::array<std::uint32_t, 32>& columns) {
  ByteTables t{};
  for (int b = 0; b < 4; ++b)
    for (std::uint32_t v = 0; v < 256; ++v)
      for (int k = 0; k < 8; ++k)
        if ((v >> k) & 1u) t[b][v] ^= columns[8 * b + k];
  return t;
}

inline constexpr std::array<ByteTables, kDimensions - 1> kByteTables = {
    byte_tables(kMatrices[1]), byte_tables(kMatrices[2]), byte_tables(kMatrices[3])};

// Coordinate `dim` (0 .. 3) of Sobol point `index`, as 32 bits of [0, 1):
// the XOR of the columns of the generator matrix selected by the index's
// bits. Dimension 0 is the van der Corput sequence, the index's bits reversed.
inline std::uint32_t sample_bits(std::uint32_t index, int dim) {
  if (dim == 0) return reverse_bits(index);
  const ByteTables& t = kByteTables[static_cast<std::size_t>(dim - 1)];
  return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^
         t[3][index >> 24];
}

// Base-2 Owen scrambling (Owen 1995) by a hash (Burley 2020, section 4, after
// Laine & Karras 2011): in bit-reversed order each output bit may depend only
// on the same and less significant input bits, which a hash of additions and
// multiplications by even constants guarantees; so in the original order
// each digit is flipped by a function of the digits above it, Owen's nested
// uniform scramble. The constants are Vegdahl's 2021 improvement of the
// Laine-Karras hash ("Building a better LK hash"; pbrt-v4's FastOwenScrambler
// and Cycles' Sobol-Burley use it), which mixes the high bits far better.
inline std::uint32_t owen_scramble(std::uint32_t x, std::uint32_t seed) {
  x = reverse_bits(x);
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return reverse_bits(x);
}

// 32 bits of [0, 1) to a float in [0, 1): the top 24 bits, exact.
inline float to_unit_float(std::uint32_t bits) {
  return static_cast<float>(bits >> 8) * (1.0f / 16777216.0f);
}

}  // namespace drift::render::sobol
