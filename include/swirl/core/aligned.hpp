// Cache-line aligned storage for particle fields.
//
// Every field array of a ParticleSet starts on a 64-byte boundary so that
// vectorised loops begin on a cache line and no two threads' blocks share the
// first line of an array.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace swirl {

inline constexpr std::size_t kFieldAlignment = 64;  // bytes

// A std::allocator replacement that returns kFieldAlignment-aligned memory.
template <class T>
struct AlignedAllocator {
  using value_type = T;

  AlignedAllocator() noexcept = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{kFieldAlignment}));
  }
  void deallocate(T* p, std::size_t) noexcept {
    ::operator delete(p, std::align_val_t{kFieldAlignment});
  }
  template <class U>
  bool operator==(const AlignedAllocator<U>&) const noexcept { return true; }
};

template <class T>
using AlignedVector = std::vector<T, AlignedAllocator<T>>;

}  // namespace swirl
