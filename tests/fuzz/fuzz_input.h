#pragma once
// Fuzz targets' view of libFuzzer's bytes as values: bytes, raw doubles (NaN, inf, denormals
// included) and values near a plausible one. Past the end every byte reads as 0, so any input
// length is a valid input.
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace tamp::fuzz {

struct Input {
  const std::uint8_t* p;
  std::size_t n;

  std::uint8_t byte() {
    if (n == 0) return 0;
    --n;
    return *p++;
  }
  /// Any double: its 8 bytes taken as they come.
  double number() {
    double d = 0;
    std::uint8_t b[sizeof(double)] = {};
    for (auto& x : b) x = byte();
    std::memcpy(&d, b, sizeof d);
    return d;
  }
  /// A value near `around` (within +-2) most of the time, an arbitrary double one time in 8.
  double value(double around) {
    const std::uint8_t k = byte();
    if (k % 8 == 0) return number();
    return around + (static_cast<int>(byte()) - 128) / 64.0;
  }
};

}  // namespace tamp::fuzz
