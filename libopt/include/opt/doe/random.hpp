// Counter-based random numbers for the design-of-experiments samplers
// (docs/doe.md): Philox4x32-10 (Random123) maps (key, counter) to 128 random
// bits with no state, so sample i's numbers are the same whichever thread,
// rank or shard draws them, in whatever order.
//
// Counter layout: {sample low 32 bits, sample high 32 bits, stream, domain}.
// uniform() and random_bits() use domain 0; the samplers' internal uses
// (Feistel round keys, Sobol scrambles, derived seeds) take their own domain
// words (namespace domain below), so no two uses ever share a counter.
#pragma once

#include <Random123/philox.h>

#include <array>
#include <cstdint>

namespace opt::doe {

// The fourth counter word: which use a draw belongs to.
namespace domain {
constexpr std::uint32_t sample = 0;           // uniform(), random_bits()
constexpr std::uint32_t feistel = 1;          // LHS permutations: feistel + round (4 rounds)
constexpr std::uint32_t sobol_scramble = 16;  // Sobol' scramble matrices and shifts
constexpr std::uint32_t derived_seed = 17;    // keys of maximin LHS candidates
constexpr std::uint32_t status_map = 18;      // which samples the status map draws
}  // namespace domain

// The raw generator: Philox4x32-10 of counter {sample, stream, domain word}
// under key = the seed's two 32-bit halves (low first).
inline std::array<std::uint32_t, 4> philox(std::uint64_t seed, std::uint64_t sample,
                                           std::uint32_t stream, std::uint32_t domain_word) {
  using Generator = r123::Philox4x32_R<10>;
  const Generator::key_type key = {
      {static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}};
  const Generator::ctr_type counter = {{static_cast<std::uint32_t>(sample),
                                        static_cast<std::uint32_t>(sample >> 32), stream, domain_word}};
  const Generator::ctr_type r = Generator()(counter, key);
  return {r[0], r[1], r[2], r[3]};
}

// Words 0 (low) and 1 (high) of philox(): 64 bits for any domain.
inline std::uint64_t philox_bits(std::uint64_t seed, std::uint64_t sample, std::uint32_t stream,
                                 std::uint32_t domain_word) {
  const auto r = philox(seed, sample, stream, domain_word);
  return static_cast<std::uint64_t>(r[0]) | (static_cast<std::uint64_t>(r[1]) << 32);
}

// 64 random bits for (seed, sample, stream): words 0 (low) and 1 (high) of
// Philox4x32-10 with counter {sample low, sample high, stream, 0}.
inline std::uint64_t random_bits(std::uint64_t seed, std::uint64_t sample, std::uint32_t stream) {
  return philox_bits(seed, sample, stream, domain::sample);
}

// A uniform number in [0, 1) with 53 random bits: the top 53 of random_bits,
// so every value is a multiple of 2^-53 and 1 is never reached.
inline double uniform(std::uint64_t seed, std::uint64_t sample, std::uint32_t stream) {
  return static_cast<double>(random_bits(seed, sample, stream) >> 11) * 0x1p-53;
}

}  // namespace opt::doe
