// Bit-for-bit equality of two arrays: the AVX2 kernels must give exactly their portable loops'
// results, where == would call -0 and +0 equal and NaN unequal to itself.
#pragma once

#include <cstring>
#include <span>
#include <vector>

namespace resecto::testing {

template <class T>
bool same_bits(std::span<const T> a, std::span<const T> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}
template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return same_bits(std::span<const T>(a), std::span<const T>(b));
}

}  // namespace resecto::testing
