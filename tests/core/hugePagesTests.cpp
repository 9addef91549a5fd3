#include <catch2/catch.hpp>
#include "hugePages.hpp"

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include <sys/mman.h>

using namespace mba;

namespace {

/// The kernel's transparent-huge-page mode: "always", "madvise", "never", or
/// "" where the kernel has none
std::string thpMode()
{
    std::ifstream f("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    std::getline(f, line);
    const auto a = line.find('['), b = line.find(']');
    return a == std::string::npos || b == std::string::npos ? "" : line.substr(a + 1, b - a - 1);
}

/// kB of huge pages backing the mapping that holds address p (/proc/self/smaps)
long hugeKBAt(const void* p)
{
    const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(p);
    std::ifstream f("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(f, line))
    {
        if (line.find("AnonHugePages:") == 0)
        {
            if (inside) return std::stol(line.substr(14));
            continue;
        }
        // a mapping's first line: "lo-hi perms offset dev inode [name]"
        std::uintptr_t lo, hi;
        char dash;
        std::istringstream s(line);
        if (line.find(':') > line.find(' ') && s >> std::hex >> lo >> dash >> hi && dash == '-') inside = lo <= a && a < hi;
    }
    return -1;
}

} // namespace

TEST_CASE("Vectors on huge pages keep their values through every growth", "[core][memory]")
{
    // small (operator new) to large (a mapping of its own) and larger, copies
    hugeVector<double> v{1.5, 2.5, 3.5};
    for (const std::size_t n : {std::size_t(100), std::size_t(1) << 19, std::size_t(3) << 20})
    {
        v.resize(n, -1.0);
        REQUIRE(v.size() == n);
        CHECK(v[0] == 1.5);
        CHECK(v[2] == 3.5);
        CHECK(v[3] == -1.0);
        CHECK(v[n - 1] == -1.0);
    }
    const hugeVector<double> w(v);
    CHECK((w == v));      // (not decomposed: Catch would print 3M values)
    v.assign(7, 4.0);
    CHECK(v == hugeVector<double>(7, 4.0));
}

TEST_CASE("Large vectors get huge pages where the kernel offers them", "[core][memory]")
{
    // A range without a whole aligned huge page is left alone
    std::vector<double> small(1000);
    CHECK_FALSE(adviseHugePages(small.data(), small.size()*sizeof(double)));

    // 16 MiB, written: its own mapping, whose aligned interior is huge pages
    // where the kernel hands them out (THP "always" or "madvise") and none
    // where it does not ("never", or no THP): either way a checked figure
    const std::string mode = thpMode();
    hugeVector<double> v(std::size_t(1) << 21, 1.0);
    const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(v.data());
    const std::uintptr_t page = (a + hugePageBytes - 1) & ~std::uintptr_t(hugePageBytes - 1);
    const long kB = hugeKBAt(reinterpret_cast<const void*>(page));
    INFO("THP mode '" << mode << "': " << kB << " kB of huge pages in the mapping");
    REQUIRE(kB >= 0);     // the mapping was found in /proc/self/smaps
    if (mode == "always" || mode == "madvise")
    {
        CHECK(kB >= 2048*7);
    }
    else
    {
        CHECK(kB == 0);
    }
}

TEST_CASE("Memory already written moves to huge pages with its values", "[core][memory]")
{
    std::vector<double> small(1000, 2.0);
    CHECK_FALSE(collapseHugePages(small.data(), small.size()*sizeof(double)));
    CHECK(small[999] == 2.0);

    // 16 MiB of a mapping never advised, written on 4 KiB pages (as an
    // OpenFOAM field), then collapsed: the same values, and where the kernel
    // does it (Linux 6.1 on; MADV_COLLAPSE does not follow the THP mode) its
    // aligned interior on huge pages
    const std::size_t n = std::size_t(1) << 21, bytes = n*sizeof(double);
    void* m = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    REQUIRE(m != MAP_FAILED);
    double* v = static_cast<double*>(m);
    for (std::size_t i = 0; i < n; ++i) v[i] = 0.5*double(i) - 7.0;
    const std::string mode = thpMode();
    const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(v);
    const void* page = reinterpret_cast<const void*>((a + hugePageBytes - 1) & ~std::uintptr_t(hugePageBytes - 1));
    if (mode == "madvise" || mode == "never") CHECK(hugeKBAt(page) == 0);
    const bool collapsed = collapseHugePages(v, bytes);
    const long kB = hugeKBAt(page);
    INFO("THP mode '" << mode << "', collapsed " << collapsed << ": " << kB << " kB of huge pages in the mapping");
    if (collapsed) CHECK(kB >= 2048*7);
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < n; ++i) wrong += v[i] != 0.5*double(i) - 7.0;
    CHECK(wrong == 0);
    munmap(m, bytes);
}
