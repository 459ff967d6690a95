// Reads structured values from a fuzzer's byte string (bounded, deterministic, never throws):
// the shared front end of the geometry fuzzers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace inbetween::fuzz {

class FuzzInput {
 public:
  FuzzInput(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  uint8_t Byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  // In [lo, hi].
  int Int(int lo, int hi) { return lo + Byte() % (hi - lo + 1); }
  // A coordinate on a coarse grid (duplicates, collinear points and touching segments are
  // common), sometimes nudged by a tiny amount (near-degenerate input).
  double Coordinate() {
    const double grid = static_cast<double>(Byte() % 33);
    const uint8_t nudge = Byte();
    if (nudge < 200) return grid;
    return grid + (static_cast<double>(nudge) - 227.5) * 1e-10;
  }
  double Double() {
    double v = 0;
    uint8_t raw[8] = {};
    for (uint8_t& b : raw) b = Byte();
    std::memcpy(&v, raw, sizeof v);
    return v;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

}  // namespace inbetween::fuzz
