// bireg: reproducible random permutations for permutation tests.
//
// Permutation b of a test with seed S depends on (S, b) only: its own
// SplitMix64 stream (Steele, Lea and Flood, "Fast splittable pseudorandom
// number generators", 2014) seeded with mix(S ^ mix(b + c)), shuffled by
// Fisher-Yates with a fixed unbiased draw (rejection of the 2^64 mod n
// lowest values). std::shuffle and std::uniform_int_distribution are
// implementation-defined, so results would differ between standard
// libraries; these do not, and permutations can be generated in any order
// or on any number of threads with identical results.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace bireg {

class PermutationStream {
 public:
  PermutationStream(std::uint64_t seed, std::uint64_t index)
      : state_(mix(seed ^ mix(index + 0x632BE59BD9B4E019ULL))) {}

  // SplitMix64.
  std::uint64_t next() {
    state_ += 0x9E3779B97F4A7C15ULL;
    return mix(state_);
  }

  // Uniform in [0, n), n >= 1, without modulo bias.
  std::uint64_t below(std::uint64_t n) {
    const std::uint64_t threshold = (0 - n) % n;  // 2^64 mod n
    std::uint64_t x = next();
    while (x < threshold)
      x = next();
    return x % n;
  }

 private:
  static std::uint64_t mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  std::uint64_t state_;
};

// Writes permutation b of 0 .. n-1 for `seed` into `permutation` (resized
// to n; no allocation once it has the capacity).
inline void permutation(std::uint64_t seed, std::uint64_t b, std::size_t n,
                        std::vector<std::size_t>& permutation) {
  permutation.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    permutation[i] = i;
  PermutationStream stream(seed, b);
  for (std::size_t i = n; i > 1; --i) {
    const std::size_t j = static_cast<std::size_t>(stream.below(i));
    std::swap(permutation[i - 1], permutation[j]);
  }
}

}  // namespace bireg
