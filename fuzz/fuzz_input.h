// What both libFuzzer targets (core_fuzzer.cpp, nbody_fuzzer.cpp) share: the input reader
// and the invariant check that aborts with a one-line reason (so libFuzzer saves the input
// as a crash).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

#define FUZZ_CHECK(condition, what)                                                               \
  do {                                                                                            \
    if (!(condition)) {                                                                           \
      std::fprintf(stderr, "invariant violated: %s (%s, line %d)\n", what, #condition, __LINE__); \
      std::abort();                                                                               \
    }                                                                                             \
  } while (0)

namespace collision_lab {
namespace fuzz {

/// Reads a fuzz input front to back. Callers check has() before each read.
class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool has(std::size_t bytes) const { return size_ - at_ >= bytes; }
  std::uint8_t byte() { return data_[at_++]; }
  /// 8 bytes: a little-endian IEEE double, any bit pattern (NaN and inf too).
  double rawDouble() {
    std::uint64_t bits = 0;
    for (int k = 0; k < 8; ++k) bits |= std::uint64_t{byte()} << (8 * k);
    double x;
    std::memcpy(&x, &bits, sizeof x);
    return x;
  }
  std::vector<double> rawDoubles(std::size_t n) {
    std::vector<double> out(n);
    for (double& x : out) x = rawDouble();
    return out;
  }
  /// 4 bytes: int16 mantissa, int16 exponent (little-endian): mantissa * 10^(exp % 340);
  /// mantissa -32768 / -32767 / -32766 stand for +inf / -inf / NaN.
  double compactDouble() {
    const auto mantissa = static_cast<std::int16_t>(byte() | (byte() << 8));
    const auto exponent = static_cast<std::int16_t>(byte() | (byte() << 8)) % 340;
    if (mantissa == -32768) return std::numeric_limits<double>::infinity();
    if (mantissa == -32767) return -std::numeric_limits<double>::infinity();
    if (mantissa == -32766) return std::numeric_limits<double>::quiet_NaN();
    // Divide for negative exponents so that e.g. 3 * 10^-1 is the double nearest 0.3.
    return exponent >= 0 ? mantissa * std::pow(10.0, exponent) : mantissa / std::pow(10.0, -exponent);
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

}  // namespace fuzz
}  // namespace collision_lab
