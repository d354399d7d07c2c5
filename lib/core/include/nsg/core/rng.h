#pragma once
// Portable seeded random numbers: xoshiro256** seeded by SplitMix64, with our own
// distributions (the std:: distributions differ between standard libraries, which would
// break byte-identical outputs across machines).
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace nsg {

class Rng {
 public:
  // `stream` derives independent sequences from one seed (e.g. one per scene or tile), so
  // results do not depend on which thread consumes which stream.
  explicit Rng(uint64_t seed, uint64_t stream = 0);

  uint64_t next_u64();
  // Uniform in [0, 1) with 53 random bits.
  double uniform();
  // Uniform in [lo, hi).
  double uniform(double lo, double hi);
  // Uniform integer in [0, n) without modulo bias (Lemire's method); n > 0.
  uint64_t uniform_int(uint64_t n);
  // Uniform integer in [lo, hi] inclusive.
  int64_t uniform_int(int64_t lo, int64_t hi);
  // Standard normal (Box–Muller, one value per call).
  double normal();
  double normal(double mean, double stddev) { return mean + stddev * normal(); }
  bool bernoulli(double p) { return uniform() < p; }

  template <typename T>
  void shuffle(std::vector<T>& v) {
    for (size_t i = v.size(); i > 1; --i) {
      const size_t j = static_cast<size_t>(uniform_int(i));
      std::swap(v[i - 1], v[j]);
    }
  }

 private:
  uint64_t s_[4];
};

// SplitMix64 finaliser: a good 64-bit mix for hashing seeds and ids together.
uint64_t mix64(uint64_t x);
// Stable hash of a byte string (FNV-1a folded through mix64); not cryptographic.
uint64_t hash_string(const char* data, size_t size);

}  // namespace nsg
