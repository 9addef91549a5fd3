#include "hugePages.hpp"

#include <cstdint>
#include <new>
#include <utility>
#ifdef __linux__
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace mba {

namespace {

#ifdef __linux__
/// MADV_COLLAPSE (Linux 6.1; glibc's headers name it from 2.37 on)
#ifdef MADV_COLLAPSE
constexpr int madviseCollapse = MADV_COLLAPSE;
#else
constexpr int madviseCollapse = 25;
#endif

/// bytes rounded up to whole pages (what a mapping of them spans)
std::size_t mappedBytes(std::size_t bytes)
{
    const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
    return (bytes + page - 1)/page*page;
}

/// The whole huge pages inside [p, p + bytes): lo, hi (hi <= lo: none)
std::pair<std::uintptr_t, std::uintptr_t> hugePagesIn(const void* p, std::size_t bytes)
{
    const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(p);
    return {(a + hugePageBytes - 1) & ~std::uintptr_t(hugePageBytes - 1),
            (a + bytes) & ~std::uintptr_t(hugePageBytes - 1)};
}
#endif

} // namespace

bool adviseHugePages(void* p, std::size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // the whole huge pages inside the range (an allocation's ends share
    // their pages with other memory: they are left as they are)
    const auto r = hugePagesIn(p, bytes);
    if (!p || r.second <= r.first) return false;
    return madvise(reinterpret_cast<void*>(r.first), r.second - r.first, MADV_HUGEPAGE) == 0;
#else
    (void)p;
    (void)bytes;
    return false;
#endif
}

bool collapseHugePages(const void* p, std::size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (!adviseHugePages(const_cast<void*>(p), bytes)) return false;
    const auto r = hugePagesIn(p, bytes);
    return madvise(reinterpret_cast<void*>(r.first), r.second - r.first, madviseCollapse) == 0;
#else
    (void)p;
    (void)bytes;
    return false;
#endif
}

void* allocateHuge(std::size_t bytes)
{
#ifdef __linux__
    if (bytes >= hugePageBytes)
    {
        void* p = mmap(nullptr, mappedBytes(bytes), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
        adviseHugePages(p, bytes);
        return p;
    }
#endif
    return ::operator new(bytes);
}

void freeHuge(void* p, std::size_t bytes) noexcept
{
#ifdef __linux__
    if (bytes >= hugePageBytes)
    {
        munmap(p, mappedBytes(bytes));
        return;
    }
#endif
    ::operator delete(p);
}

} // namespace mba
