#include "hugePages.hpp"

#include <array>
#include <cstdint>
#include <mutex>
#include <new>
#ifdef __linux__
#include <sys/mman.h>
#endif

namespace mba {

namespace {

#if defined(__linux__) && defined(MADV_HUGEPAGE)
constexpr int adviceHuge = MADV_HUGEPAGE;
/// MADV_COLLAPSE (Linux 6.1; glibc's headers name it from 2.37 on)
#ifdef MADV_COLLAPSE
constexpr int adviceCollapse = MADV_COLLAPSE;
#else
constexpr int adviceCollapse = 25;
#endif

/// madvise(advice) on the whole huge pages inside [p, p + bytes) (an
/// allocation's ends share their pages with other memory: they are left as
/// they are); false where it holds none or the kernel refuses
bool adviseWholePages(const void* p, std::size_t bytes, int advice)
{
    const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t lo = (a + hugePageBytes - 1) & ~std::uintptr_t(hugePageBytes - 1);
    const std::uintptr_t hi = (a + bytes) & ~std::uintptr_t(hugePageBytes - 1);
    if (!p || hi <= lo) return false;
    return madvise(reinterpret_cast<void*>(lo), hi - lo, advice) == 0;
}
#else
constexpr int adviceHuge = 0, adviceCollapse = 0;
bool adviseWholePages(const void*, std::size_t, int) { return false; }
#endif

// Under AddressSanitizer the pool would hide the arrays from its checks: the
// sanitizer's own allocations stand in for it (and for the aligned mappings)
#if defined(__linux__) && defined(MADV_HUGEPAGE) && !defined(__SANITIZE_ADDRESS__)
#define HUGE_POOL

/// bytes rounded up to whole huge pages
std::size_t wholeHugePages(std::size_t bytes)
{
    return (bytes + hugePageBytes - 1)/hugePageBytes*hugePageBytes;
}

/// A fresh mapping of bytes (whole huge pages) that starts on a huge-page
/// boundary, advised for huge pages: every page of it is huge where the
/// kernel hands them out (a plain mapping starts anywhere, and its first and
/// last 2 MiB are then 4 KiB pages)
void* mapHuge(std::size_t bytes)
{
    const std::size_t span = bytes + hugePageBytes;
    void* m = mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) throw std::bad_alloc();
    // the slack before and after the aligned range, never touched, goes back
    char* const lo = static_cast<char*>(m);
    char* const at = reinterpret_cast<char*>
    (
        (reinterpret_cast<std::uintptr_t>(lo) + hugePageBytes - 1) & ~std::uintptr_t(hugePageBytes - 1)
    );
    if (at > lo) munmap(lo, std::size_t(at - lo));
    if (lo + span > at + bytes) munmap(at + bytes, std::size_t(lo + span - (at + bytes)));
    madvise(at, bytes, adviceHuge);
    return at;
}

/// Arrays from this size up to hugePageBytes come from the pool
constexpr std::size_t smallestPooled = std::size_t(16) << 10;

/// The pool's size class of bytes: blocks of 2^class bytes
int sizeClass(std::size_t bytes)
{
    int c = 0;
    while ((std::size_t(1) << c) < bytes) ++c;
    return c;
}

/// The arrays under a huge page (a fit's per-level tables, stencils,
/// residuals): each on 4 KiB pages of its own, they would cost a page walk
/// per 4 KiB where one per 2 MiB does. Blocks of a power of two bytes, carved
/// from huge pages of their class and kept for reuse (never unmapped: an
/// unmapping is what makes every page dear again on some virtual machines).
class hugePool
{
    static constexpr int nClasses = 22;  // up to 2^21 = hugePageBytes
    std::mutex mutex_;
    std::array<void*, nClasses> free_{};     // per class: freed blocks, linked through their first word
    std::array<char*, nClasses> next_{};     // per class: the rest of its newest huge page
    std::array<std::size_t, nClasses> left_{};

public:
    void* take(int c)
    {
        const std::size_t size = std::size_t(1) << c;
        std::lock_guard<std::mutex> lock(mutex_);
        if (void* p = free_[c])
        {
            free_[c] = *static_cast<void**>(p);
            return p;
        }
        if (left_[c] < size)
        {
            next_[c] = static_cast<char*>(mapHuge(hugePageBytes));
            left_[c] = hugePageBytes;
        }
        void* p = next_[c];
        next_[c] += size;
        left_[c] -= size;
        return p;
    }

    void give(int c, void* p) noexcept
    {
        std::lock_guard<std::mutex> lock(mutex_);
        *static_cast<void**>(p) = free_[c];
        free_[c] = p;
    }
};

hugePool& pool()
{
    static hugePool* const p = new hugePool;  // (never destroyed: arrays of static objects may outlive any order)
    return *p;
}
#endif

} // namespace

bool adviseHugePages(void* p, std::size_t bytes)
{
    return adviseWholePages(p, bytes, adviceHuge);
}

bool collapseHugePages(const void* p, std::size_t bytes)
{
    return adviseWholePages(p, bytes, adviceHuge) && adviseWholePages(p, bytes, adviceCollapse);
}

void* allocateHuge(std::size_t bytes)
{
#ifdef HUGE_POOL
    if (bytes >= hugePageBytes) return mapHuge(wholeHugePages(bytes));
    if (bytes >= smallestPooled) return pool().take(sizeClass(bytes));
#endif
    return ::operator new(bytes);
}

void freeHuge(void* p, std::size_t bytes) noexcept
{
#ifdef HUGE_POOL
    if (bytes >= hugePageBytes)
    {
        munmap(p, wholeHugePages(bytes));
        return;
    }
    if (bytes >= smallestPooled)
    {
        pool().give(sizeClass(bytes), p);
        return;
    }
#endif
    ::operator delete(p);
}

} // namespace mba
