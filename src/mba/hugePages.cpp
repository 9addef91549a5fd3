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

} // namespace

bool adviseHugePages(void* p, std::size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // the whole huge pages inside the range (an allocation's ends share
    // their pages with other memory)
    const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t lo = (a + hugePageBytes - 1) & ~std::uintptr_t(hugePageBytes - 1);
    const std::uintptr_t hi = (a + bytes) & ~std::uintptr_t(hugePageBytes - 1);
    if (!p || hi <= lo) return false;
    return madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE) == 0;
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
