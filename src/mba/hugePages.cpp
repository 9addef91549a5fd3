#include "hugePages.hpp"

#include <cstdint>
#include <new>
#ifdef __linux__
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace mba {

namespace {

#ifdef __linux__
/// bytes rounded up to whole pages (what a mapping of them spans)
std::size_t mappedBytes(std::size_t bytes)
{
    const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
    return (bytes + page - 1)/page*page;
}
#endif

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
