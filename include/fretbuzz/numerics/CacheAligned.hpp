#pragma once
// Storage for the arrays the kernels sweep at every step (the modal state, the propagator's
// coefficients, the contact rows), starting on a cache line: a vector load of the kernels
// then never straddles two lines. With malloc's 16-byte alignment whether it did depended on
// the heap's layout, which moved a run's speed from one build to another (docs/performance.md,
// figures behind choices in the code).
#include <cstddef>
#include <new>
#include <vector>

namespace fretbuzz {

template <class T>
struct CacheLineAllocator {
    using value_type = T;
    static constexpr std::align_val_t kAlignment{64};

    CacheLineAllocator() = default;
    template <class U>
    constexpr CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kAlignment)); }
    void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, kAlignment); }

    template <class U>
    bool operator==(const CacheLineAllocator<U>&) const noexcept {
        return true;
    }
};

// A vector of doubles whose first element starts a cache line.
using AlignedVector = std::vector<double, CacheLineAllocator<double>>;

}  // namespace fretbuzz
