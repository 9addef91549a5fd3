// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Transparent huge pages for the large arrays that every fit and evaluation
// sweeps (lattices, per-point tables). On machines whose page-table walks are
// costly (some virtual machines) a sweep over arrays on 4 KiB pages costs
// several times one over the same arrays on 2 MiB pages; elsewhere it changes
// little. Linux with transparent huge pages in "madvise" (or "always") mode;
// elsewhere plain allocations. Values are never affected.
#ifndef MBA_HUGEPAGES_HPP
#define MBA_HUGEPAGES_HPP

#include <cstddef>
#include <vector>

namespace mba {

/// Arrays smaller than this are allocated as usual (they hold no whole huge page)
constexpr std::size_t hugePageBytes = std::size_t(2) << 20;

/// Asks the kernel to back the whole 2 MiB pages inside [p, p + bytes) with
/// transparent huge pages. Only memory not yet written is affected: call it
/// between allocating and first writing (memory that malloc hands out again
/// may have been written before: then it does nothing). Returns whether the
/// range holds a whole huge page and the kernel took the advice.
bool adviseHugePages(void* p, std::size_t bytes);

/// Backs the whole 2 MiB pages inside [p, p + bytes) with huge pages now,
/// also where the memory has been written (its contents kept): the kernel
/// copies them into huge pages (MADV_COLLAPSE, Linux 6.1 and later), else it
/// takes the advice for later (MADV_HUGEPAGE). For mesh-sized arrays made by
/// others (OpenFOAM's fields), once per plan: moving 4 KiB pages costs a few
/// ms a MiB, pages that are huge already nothing. Returns whether the pages
/// are huge now.
bool collapseHugePages(const void* p, std::size_t bytes);

/// Memory for bytes: at least hugePageBytes, a fresh anonymous mapping advised
/// for huge pages (so never written before); less, operator new. Throws
/// std::bad_alloc.
void* allocateHuge(std::size_t bytes);

/// Frees what allocateHuge(bytes) returned
void freeHuge(void* p, std::size_t bytes) noexcept;

/// Allocator of allocateHuge/freeHuge, for the core's large arrays
template <class T>
struct hugeAllocator
{
    typedef T value_type;
    hugeAllocator() = default;
    template <class U> hugeAllocator(const hugeAllocator<U>&) {}
    T* allocate(std::size_t n) { return static_cast<T*>(allocateHuge(n*sizeof(T))); }
    void deallocate(T* p, std::size_t n) noexcept { freeHuge(p, n*sizeof(T)); }
    template <class U> bool operator==(const hugeAllocator<U>&) const { return true; }
    template <class U> bool operator!=(const hugeAllocator<U>&) const { return false; }
};

/// A vector on huge pages when large
template <class T> using hugeVector = std::vector<T, hugeAllocator<T>>;

} // namespace mba
#endif
