#pragma once
/// \file Permutation.hpp
/// Reordering of structure-of-arrays data (particles, tracers and whatever they carry) by one
/// permutation, so every array a sort touches moves the same way.

#include <cstdint>
#include <vector>

namespace rcfd {

/// a[k] becomes the old a[from[k]] for every k (`from` lists, for each new position, the old one).
/// `scratch` receives the old array (kept by callers that reorder often, to spare the allocation's
/// page faults). Large arrays are gathered in parallel; the result does not depend on it.
template <class T, class Index>
void applyPermutation(std::vector<T>& a, const std::vector<Index>& from, std::vector<T>& scratch) {
  constexpr std::int64_t kParallelFrom = 1 << 16;
  const std::int64_t n = std::int64_t(from.size());
  scratch.resize(from.size());
#pragma omp parallel for schedule(static) if (n > kParallelFrom)
  for (std::int64_t k = 0; k < n; ++k) scratch[std::size_t(k)] = a[std::size_t(from[std::size_t(k)])];
  a.swap(scratch);
}

template <class T, class Index>
void applyPermutation(std::vector<T>& a, const std::vector<Index>& from) {
  std::vector<T> scratch;
  applyPermutation(a, from, scratch);
}

}  // namespace rcfd
