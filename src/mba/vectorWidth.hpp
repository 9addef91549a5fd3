// bsplineMorph: OpenFOAM-free multilevel B-spline core
// The kernels' vector width: the stencil kernels are compiled twice on
// x86-64, for any processor (vectors of two doubles) and for AVX2 with FMA
// (vectors of four), and the wider ones run where the processor has them.
#ifndef MBA_VECTORWIDTH_HPP
#define MBA_VECTORWIDTH_HPP

namespace mba {

#if defined(__GNUC__) && defined(__x86_64__)
/// Kernels also compiled for AVX2 with FMA (vectors of four doubles), used
/// where the processor has them; the library itself is built for any x86-64
#define MBA_WIDE_VECTORS 1
#define MBA_WIDE_TARGET __attribute__((target("avx2,fma")))
#endif

namespace detail {
/// Whether the processor runs the kernels compiled for AVX2 with FMA
inline bool cpuHasWideVectors()
{
#ifdef MBA_WIDE_VECTORS
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
    return false;
#endif
}

inline bool& wideFlag()
{
    static bool on = cpuHasWideVectors();
    return on;
}
}

/// Whether the kernels run on vectors of four doubles (AVX2 with FMA, chosen
/// at run time on x86-64). Their results differ from the two-double kernels'
/// by rounding only.
inline bool wideVectors() { return detail::wideFlag(); }

/// Turns them off, or on again where the processor has them; returns the
/// previous setting. For tests comparing the two.
inline bool useWideVectors(bool on)
{
    const bool was = detail::wideFlag();
    detail::wideFlag() = on && detail::cpuHasWideVectors();
    return was;
}

/// Vectors of W doubles (GCC's vector extension): W = 2 is SSE2 on x86-64 and
/// NEON on arm64; W = 4 (AVX2) only in code compiled for it (MBA_WIDE_TARGET)
template <int W> struct vec;
template <> struct vec<2>
{
    typedef double type __attribute__((vector_size(16)));
    typedef double unaligned __attribute__((vector_size(16), aligned(8), may_alias)); ///< in arrays of double
};
template <> struct vec<4>
{
    typedef double type __attribute__((vector_size(32)));
    typedef double unaligned __attribute__((vector_size(32), aligned(8), may_alias));
};

} // namespace mba
#endif
