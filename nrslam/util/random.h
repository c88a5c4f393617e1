// util: deterministic random numbers.
//
// The simulator promises byte-identical output for the same seed, on any thread count. The
// standard distributions are implementation-defined, so we derive every random value from
// splitmix64 ourselves: a sequential generator for scene building and a stateless hash for
// per-pixel noise, whose value depends only on its coordinates, never on evaluation order.
#pragma once

#include <cmath>
#include <cstdint>

namespace nrslam {

inline uint64_t SplitMix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Hash of several integer coordinates; order matters.
inline uint64_t HashCoordinates(uint64_t a, uint64_t b, uint64_t c = 0, uint64_t d = 0) {
  return SplitMix64(SplitMix64(SplitMix64(SplitMix64(a) ^ b) ^ c) ^ d);
}

// Uniform in [0, 1) from the top 53 bits.
inline double UnitFromBits(uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

// Standard normal from a hash (Box-Muller on two derived uniforms).
inline double NormalFromHash(uint64_t hash) {
  const double u1 = UnitFromBits(SplitMix64(hash)) + 0x1.0p-54;  // never 0
  const double u2 = UnitFromBits(SplitMix64(hash ^ 0x5851f42d4c957f2dULL));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// Approximately standard normal from one hash: the sum of four 16-bit uniforms (Irwin–Hall),
// rescaled. Far cheaper than NormalFromHash and plenty for sensor noise.
inline double FastNormalFromHash(uint64_t hash) {
  const uint64_t bits = SplitMix64(hash);
  const double sum = static_cast<double>((bits & 0xffff) + ((bits >> 16) & 0xffff) + ((bits >> 32) & 0xffff) +
                                         (bits >> 48));
  return (sum / 65535.0 - 2.0) * 1.7320508075688772;  // variance of the sum is 4/12
}

class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t NextBits() { return SplitMix64(state_++ * 0x2545f4914f6cdd1dULL + 0x9e37ULL); }
  double Uniform() { return UnitFromBits(NextBits()); }
  double Uniform(double low, double high) { return low + (high - low) * Uniform(); }
  double Normal() { return NormalFromHash(NextBits()); }

 private:
  uint64_t state_;
};

}  // namespace nrslam
