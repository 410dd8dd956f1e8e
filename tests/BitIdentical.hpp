#pragma once
/// \file BitIdentical.hpp
/// Bit-for-bit equality of two arrays, the check of every determinism and resume test. memcmp on the
/// data of an empty vector passes a null pointer, which the C library does not allow (UBSan flags it).
#include <cstring>
#include <vector>

namespace rcfd::test {

template <class T>
bool bitIdentical(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

}  // namespace rcfd::test
