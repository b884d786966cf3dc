// std::vector with 64-byte aligned storage (one cache line, one AVX-512 register), for the
// population arrays that the vectorised kernels stream through. Arrays of 8 MB and more are
// aligned to 2 MB and offered to the kernel as transparent huge pages (Linux madvise): with
// 19 streams per cell the TLB misses of 4 kB pages cost D3Q19 about 10% of its speed.
#pragma once
#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace ff::lbm {

template <class T>
struct AlignedAllocator {
  using value_type = T;
  static constexpr std::align_val_t kAlign{64};
  static constexpr std::size_t kHuge = std::size_t(2) << 20, kHugeFrom = std::size_t(8) << 20;
  AlignedAllocator() = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugeFrom) return static_cast<T*>(::operator new(bytes, kAlign));
    const std::size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
    void* p = std::aligned_alloc(kHuge, rounded);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, rounded, MADV_HUGEPAGE);  // a hint: without huge pages everything still works
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) {
    if (n * sizeof(T) < kHugeFrom) ::operator delete(p, kAlign);
    else std::free(p);
  }
  template <class U>
  bool operator==(const AlignedAllocator<U>&) const { return true; }
};

template <class T>
using AlignedVector = std::vector<T, AlignedAllocator<T>>;

}  // namespace ff::lbm
