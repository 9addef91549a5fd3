#include "subdivision.hpp"

namespace mba {

namespace {

/// Coarse parents of fine node jf in one direction (uniform cubic B-spline
/// subdivision; node j lies at lo + (j - 1) h): fine node 2j - 1 = (P[j-1] +
/// 6 P[j] + P[j+1])/8, fine node 2j = (P[j] + P[j+1])/2. Parents outside
/// [lo, hi] are left out.
inline int parents(std::int64_t jf, std::int64_t lo, std::int64_t hi, std::int64_t* j, double* w)
{
    int n = 0;
    auto add = [&](std::int64_t i, double wt) { if (i >= lo && i <= hi) { j[n] = i; w[n] = wt; ++n; } };
    if (jf % 2 == 0) { add(jf/2, 0.5); add(jf/2 + 1, 0.5); }
    else { const std::int64_t c = (jf + 1)/2; add(c - 1, 0.125); add(c, 0.75); add(c + 1, 0.125); }
    return n;
}

/// One direction's pass: t[o][jf][i] = the sum over q of pw[3 jf + q]
/// g[o][pj[3 jf + q]][i] (i < inner, nc-wide at compile time where inner
/// is nc: the last direction's pass, whose rows are a node each)
template <int NC>
void refinePass(double* t, const double* g, std::int64_t outer, std::int64_t nf, std::int64_t nco,
                std::int64_t inner, const std::int64_t* pj, const double* pw)
{
    const std::int64_t n = NC > 0 ? NC : inner;
    for (std::int64_t o = 0; o < outer; ++o, t += nf*n, g += nco*n)
        for (std::int64_t jf = 0; jf < nf; ++jf)
        {
            double* tj = t + jf*n;
            const double* g0 = g + pj[3*jf]*n;
            const double* g1 = g + pj[3*jf + 1]*n;
            const double* g2 = g + pj[3*jf + 2]*n;
            const double w0 = pw[3*jf], w1 = pw[3*jf + 1], w2 = pw[3*jf + 2];
            for (std::int64_t i = 0; i < n; ++i) tj[i] = w0*g0[i] + w1*g1[i] + w2*g2[i];
        }
}

} // namespace

template <int D>
void refine(hugeVector<double>& G, const indexBox<D>& cb, const indexBox<D>& fb, int nc, hugeVector<double>& T)
{
    index<D> n;
    for (int d = 0; d < D; ++d) n[d] = cb.hi[d] - cb.lo[d] + 1;
    std::vector<std::int64_t> pj;
    std::vector<double> pw;
    for (int d = 0; d < D; ++d)
    {
        std::int64_t outer = 1, inner = nc;
        for (int e = 0; e < d; ++e) outer *= n[e];
        for (int e = d + 1; e < D; ++e) inner *= n[e];
        const std::int64_t nf = fb.hi[d] - fb.lo[d] + 1, nco = n[d];
        // Three parents a fine node (a missing one with weight 0 at coarse
        // node 0: the same sums)
        pj.assign(3*nf, 0);
        pw.assign(3*nf, 0.0);
        for (std::int64_t jf = 0; jf < nf; ++jf)
        {
            const int np = parents(fb.lo[d] + jf, cb.lo[d], cb.hi[d], &pj[3*jf], &pw[3*jf]);
            for (int q = 0; q < np; ++q) pj[3*jf + q] -= cb.lo[d];
        }
        holdAtLeast(T, std::size_t(outer*nf*inner));
        const auto pass = inner == 1 ? refinePass<1> : inner == 2 ? refinePass<2> : inner == 3 ? refinePass<3>
                                                                                               : refinePass<0>;
        pass(T.data(), G.data(), outer, nf, nco, inner, pj.data(), pw.data());
        n[d] = nf;
        G.swap(T);
    }
}

template void refine<2>(hugeVector<double>&, const indexBox<2>&, const indexBox<2>&, int, hugeVector<double>&);
template void refine<3>(hugeVector<double>&, const indexBox<3>&, const indexBox<3>&, int, hugeVector<double>&);

} // namespace mba
