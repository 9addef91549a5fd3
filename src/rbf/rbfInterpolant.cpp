#include "rbfInterpolant.hpp"
#include "collectively.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

extern "C" {
void dsytrf_(const char* uplo, const int* n, double* a, const int* lda, int* ipiv, double* work,
             const int* lwork, int* info);
void dsytrs_(const char* uplo, const int* n, const int* nrhs, const double* a, const int* lda,
             const int* ipiv, double* b, const int* ldb, int* info);
void dsycon_(const char* uplo, const int* n, const double* a, const int* lda, const int* ipiv,
             const double* anorm, double* rcond, double* work, int* iwork, int* info);
}

namespace rbf {

using mba::precondition;

kernel kernelFromName(const std::string& name)
{
    if (name == "inverseMultiquadric") return kernel::inverseMultiquadric;
    if (name == "thinPlateSpline") return kernel::thinPlateSpline;
    if (name == "wendlandC2") return kernel::wendlandC2;
    throw std::invalid_argument("rbf: unknown function '" + name
        + "'; valid: inverseMultiquadric thinPlateSpline wendlandC2");
}

std::string kernelName(kernel k)
{
    switch (k)
    {
        case kernel::inverseMultiquadric: return "inverseMultiquadric";
        case kernel::thinPlateSpline: return "thinPlateSpline";
        default: return "wendlandC2";
    }
}

void params::validate() const
{
    precondition(std::isfinite(shapeParameter) && shapeParameter > 0,
        "rbf: shapeParameter must be > 0, got " + std::to_string(shapeParameter));
    precondition(std::isfinite(supportRadius) && supportRadius > 0,
        "rbf: supportRadius must be > 0, got " + std::to_string(supportRadius));
    precondition(function != kernel::thinPlateSpline || polynomial,
        "rbf: thinPlateSpline needs the polynomial (polynomial true)");
    precondition(maxPoints >= 1, "rbf: maxPoints must be >= 1, got " + std::to_string(maxPoints));
    precondition(std::isfinite(greedyTolerance) && greedyTolerance >= 0,
        "rbf: greedyTolerance must be >= 0, got " + std::to_string(greedyTolerance));
    precondition(greedyBatch >= 1, "rbf: greedyBatch must be >= 1, got " + std::to_string(greedyBatch));
    precondition(minRcond >= 0 && minRcond < 1, "rbf: minRcond must be in [0, 1)");
}

namespace {

double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Add to centres (marking them in used) the points of x that the linear
/// polynomial needs: while the centres span fewer than D dimensions (their
/// offsets from the first, orthonormalised), the point farthest from their
/// span (the lowest index of equals; none beyond tol of it: the points
/// themselves span no more)
template <int D>
void spanPolynomial(const std::vector<point<D>>& x, double tol, std::vector<std::size_t>& centres,
                    std::vector<char>& used)
{
    std::vector<std::array<double, D>> basis;
    // r's part off the span of basis (r itself: its offset from the first centre)
    const auto offSpan = [&](std::array<double, D> r) {
        for (const auto& e : basis)
        {
            double dot = 0;
            for (int d = 0; d < D; ++d) dot += r[d]*e[d];
            for (int d = 0; d < D; ++d) r[d] -= dot*e[d];
        }
        return r;
    };
    const auto offset = [&](std::size_t i) {
        std::array<double, D> r;
        for (int d = 0; d < D; ++d) r[d] = x[i][d] - x[centres[0]][d];
        return r;
    };
    const auto grow = [&](const std::array<double, D>& r) {
        double m = 0;
        for (int d = 0; d < D; ++d) m += r[d]*r[d];
        m = std::sqrt(m);
        if (m <= tol) return false;
        std::array<double, D> e;
        for (int d = 0; d < D; ++d) e[d] = r[d]/m;
        basis.push_back(e);
        return true;
    };
    for (std::size_t k = 1; k < centres.size() && int(basis.size()) < D; ++k) grow(offSpan(offset(centres[k])));
    while (int(basis.size()) < D)
    {
        std::size_t best = x.size();
        double far = -1;
        for (std::size_t i = 0; i < x.size(); ++i)
        {
            if (used[i]) continue;
            const auto r = offSpan(offset(i));
            double m = 0;
            for (int d = 0; d < D; ++d) m += r[d]*r[d];
            if (m > far) { far = m; best = i; }
        }
        if (best == x.size() || !grow(offSpan(offset(best)))) return;
        centres.push_back(best);
        used[best] = 1;
    }
}

} // namespace

template <int D>
double interpolant<D>::phi(double r2) const
{
    switch (p_.function)
    {
        case kernel::inverseMultiquadric:
            return 1/std::sqrt(r2 + c2_);
        case kernel::thinPlateSpline:
            return r2 > 0 ? 0.5*r2*std::log(r2) : 0.0;
        default:
        {
            const double q = std::sqrt(r2)/R_;
            if (q >= 1) return 0.0;
            const double t = 1 - q;
            return t*t*t*t*(4*q + 1);
        }
    }
}

template <int D>
interpolant<D>::interpolant(const mba::communicator& comm, const params& p, int nComponents,
                            pointsView<D> control)
:
    comm_(comm), p_(p), nc_(nComponents)
{
    const double t0 = now();
    mba::collectively(comm_, [&] {
        p_.validate();
        precondition(nc_ >= 1 && nc_ <= 3, "rbf: 1 to 3 value components, got " + std::to_string(nc_));
        for (std::size_t i = 0; i < control.size; ++i)
            for (int d = 0; d < D; ++d)
                if (!std::isfinite(control[i][d]))
                    precondition(false, "rbf: control point " + std::to_string(i) + " has a non-finite coordinate");
    });

    // Gather every control point; canonical (sorted) order
    std::vector<double> mine(control.data, control.data + D*control.size);
    const auto all = comm_.allGather(mine);
    std::vector<point<D>> gathered;
    std::size_t myOffset = 0;
    for (int r = 0; r < comm_.size(); ++r)
    {
        if (r == comm_.rank()) myOffset = gathered.size();
        else stats_.gatheredBytes += std::int64_t(all[r].size()*sizeof(double));
        for (std::size_t i = 0; i + D <= all[r].size(); i += D)
        {
            point<D> x;
            for (int d = 0; d < D; ++d) x[d] = all[r][i + d];
            gathered.push_back(x);
        }
    }
    // Canonical order: sorted by coordinates quantised to 1e-10 of the
    // bounding-box diagonal; points equal at that resolution are one centre
    // (a 2D mesh's front and back points project to the same position, a few
    // ulps apart: as two centres they would make the system singular)
    mba::box<D> gb = mba::box<D>::empty();
    for (const auto& x : gathered) gb.add(x.data());
    double gdiag = 0;
    if (!gb.isEmpty()) for (int d = 0; d < D; ++d) gdiag += (gb.hi[d] - gb.lo[d])*(gb.hi[d] - gb.lo[d]);
    const double quantum = 1e-10*(gdiag > 0 ? std::sqrt(gdiag) : 1.0);
    std::vector<std::array<std::int64_t, D>> key(gathered.size());
    for (std::size_t i = 0; i < gathered.size(); ++i)
        for (int d = 0; d < D; ++d) key[i][d] = std::int64_t(std::llround((gathered[i][d] - gb.lo[d])/quantum));
    std::vector<std::size_t> order(gathered.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return key[a] < key[b] || (key[a] == key[b] && gathered[a] < gathered[b]);
    });
    std::vector<std::size_t> where(gathered.size());
    for (std::size_t k = 0; k < order.size(); ++k)
    {
        if (k > 0 && key[order[k]] == key[order[k - 1]]) { where[order[k]] = x_.size() - 1; continue; }
        where[order[k]] = x_.size();
        x_.push_back(gathered[order[k]]);
    }
    for (std::size_t i = 0; i < control.size; ++i) localToGlobal_.push_back(where[myOffset + i]);
    stats_.controlPoints = long(x_.size());

    // Scales: bounding box of all control points
    mba::box<D> b = mba::box<D>::empty();
    for (const auto& x : x_) b.add(x.data());
    double diag = 0;
    if (!b.isEmpty()) for (int d = 0; d < D; ++d) diag += (b.hi[d] - b.lo[d])*(b.hi[d] - b.lo[d]);
    diag = std::sqrt(diag);
    scale_ = diag > 0 ? diag : 1.0;
    lo_ = b.isEmpty() ? point<D>{} : b.lo;
    c2_ = (p_.shapeParameter*scale_)*(p_.shapeParameter*scale_);
    R_ = p_.supportRadius*scale_;

    if (p_.greedyTolerance == 0 || x_.empty())
    {
        std::vector<std::size_t> allCentres(x_.size());
        std::iota(allCentres.begin(), allCentres.end(), 0);
        factor(allCentres);
    }
    stats_.setupSeconds = now() - t0;
}

template <int D>
void interpolant<D>::factor(const std::vector<std::size_t>& centres)
{
    const long m = long(centres.size());
    const int np = p_.polynomial ? D + 1 : 0;
    const long n = m + (m > 0 ? np : 0);
    mba::collectively(comm_, [&] {
        precondition(m <= p_.maxPoints,
            "rbf: " + std::to_string(m) + " control points exceed maxPoints " + std::to_string(p_.maxPoints)
            + "; the dense system would need " + std::to_string(double(n)*n*8/1048576.0) + " MB per rank"
            + " (raise maxPoints if the memory is there, or "
            + (p_.greedyTolerance > 0 ? "greedyTolerance, or lower greedyBatch)" : "use greedy selection: greedyTolerance)"));
    });
    centres_ = centres;
    stats_.centres = m;
    stats_.size = n;
    lu_.assign(std::size_t(n)*n, 0.0);
    ipiv_.assign(std::size_t(n), 0);
    if (n == 0) return;
    auto A = [&](long i, long j) -> double& { return lu_[std::size_t(j)*n + i]; };
    for (long j = 0; j < m; ++j)
    {
        const point<D>& xj = x_[centres[j]];
        for (long i = 0; i < m; ++i)
        {
            const point<D>& xi = x_[centres[i]];
            double r2 = 0;
            for (int d = 0; d < D; ++d) r2 += (xi[d] - xj[d])*(xi[d] - xj[d]);
            A(i, j) = phi(r2/(p_.function == kernel::thinPlateSpline ? scale_*scale_ : 1.0));
        }
        if (np)
        {
            A(m, j) = A(j, m) = 1;
            for (int d = 0; d < D; ++d) A(m + 1 + d, j) = A(j, m + 1 + d) = (xj[d] - lo_[d])/scale_;
        }
    }
    // A coordinate that no centre varies in (the control points all in one
    // plane or on one line along the axes: a box face) leaves its polynomial
    // term undetermined: its row and column keep 1 on the diagonal alone, a
    // zero coefficient
    for (int d = 0; np && m > 0 && d < D; ++d)
    {
        double lo = HUGE_VAL, hi = -HUGE_VAL;
        for (long j = 0; j < m; ++j)
        {
            lo = std::min(lo, x_[centres[j]][d]);
            hi = std::max(hi, x_[centres[j]][d]);
        }
        if (hi - lo > 1e-12*scale_) continue;
        for (long j = 0; j < m; ++j) A(m + 1 + d, j) = A(j, m + 1 + d) = 0;
        A(m + 1 + d, m + 1 + d) = 1;
    }
    double anorm = 0;
    for (long j = 0; j < n; ++j)
    {
        double s = 0;
        for (long i = 0; i < n; ++i) s += std::abs(A(i, j));
        anorm = std::max(anorm, s);
    }
    const int N = int(n);
    int info = 0, lwork = -1;
    double wq;
    dsytrf_("L", &N, lu_.data(), &N, ipiv_.data(), &wq, &lwork, &info);
    lwork = std::max(1, int(wq));
    std::vector<double> work(std::size_t(std::max(lwork, 2*N)));
    dsytrf_("L", &N, lu_.data(), &N, ipiv_.data(), work.data(), &lwork, &info);
    double rcond = 0;
    if (info == 0)
    {
        std::vector<int> iwork(N);
        dsycon_("L", &N, lu_.data(), &N, ipiv_.data(), &anorm, &rcond, work.data(), iwork.data(), &info);
    }
    stats_.rcond = rcond;
    stats_.bytes = double(lu_.size())*sizeof(double);
    mba::collectively(comm_, [&] {
        std::ostringstream msg;
        msg << "rbf: the " << n << "x" << n << " " << kernelName(p_.function)
            << " system is singular or ill-conditioned (reciprocal condition " << rcond
            << " < minRcond " << p_.minRcond << "): duplicate or nearly coincident control"
            " points, control points all in one plane or on one line oblique to the axes (the"
            " linear polynomial needs them to span the mesh's dimensions), or shapeParameter /"
            " supportRadius far too large for the point spacing";
        precondition(info == 0 && rcond >= p_.minRcond, msg.str());
    });
}

template <int D>
void interpolant<D>::solve(const std::vector<double>& v)
{
    const long m = long(centres_.size()), n = stats_.size;
    coeff_.assign(std::size_t(n)*nc_, 0.0);
    if (n == 0) return;
    for (int c = 0; c < nc_; ++c)
        for (long i = 0; i < m; ++i) coeff_[std::size_t(c)*n + i] = v[centres_[i]*nc_ + c];
    const int N = int(n), nrhs = nc_;
    int info = 0;
    dsytrs_("L", &N, &nrhs, lu_.data(), &N, ipiv_.data(), coeff_.data(), &N, &info);
    if (info != 0) throw std::runtime_error("rbf: dsytrs failed");
}

template <int D>
void interpolant<D>::fit(const std::vector<double>& values)
{
    mba::collectively(comm_, [&] {
        precondition(values.size() == localToGlobal_.size()*nc_,
            "rbf: " + std::to_string(values.size()) + " control values, expected "
            + std::to_string(localToGlobal_.size()*nc_));
        for (std::size_t i = 0; i < values.size(); ++i)
            if (!std::isfinite(values[i]))
                precondition(false, "rbf: control value " + std::to_string(i/nc_) + " is not finite");
    });
    // Gather the values into the canonical order (duplicates: the last wins; they are equal)
    std::vector<double> mine(values);
    const auto all = comm_.allGather(mine);
    const auto allIdx = comm_.allGather(std::vector<std::uint64_t>(localToGlobal_.begin(), localToGlobal_.end()));
    std::vector<double> v(x_.size()*nc_, 0.0);
    for (int r = 0; r < comm_.size(); ++r)
        for (std::size_t i = 0; i < allIdx[r].size(); ++i)
            for (int c = 0; c < nc_; ++c) v[allIdx[r][i]*nc_ + c] = all[r][i*nc_ + c];

    if (p_.greedyTolerance > 0 && centres_.empty() && !x_.empty())
    {
        // Greedy selection: add the points of largest error until within tolerance
        const double t0 = now();
        double vmax = 0;
        for (double x : v) vmax = std::max(vmax, std::abs(x));
        std::vector<char> used(x_.size(), 0);
        std::vector<std::size_t> centres;
        const std::size_t step = std::max<std::size_t>(1, x_.size()/std::size_t(p_.greedyBatch));
        for (std::size_t i = 0; i < x_.size(); i += step) { centres.push_back(i); used[i] = 1; }
        // (a small batch, or one in a plane, would leave the polynomial's
        // coefficients undetermined: a singular first system)
        if (p_.polynomial) spanPolynomial<D>(x_, 1e-9*scale_, centres, used);
        std::vector<double> err(x_.size()), s(nc_);
        for (;;)
        {
            factor(centres);
            solve(v);
            double emax = 0;
            for (std::size_t i = 0; i < x_.size(); ++i)
            {
                std::fill(s.begin(), s.end(), 0.0);
                evaluateAt(x_[i].data(), s.data());
                double e = 0;
                for (int c = 0; c < nc_; ++c) e = std::max(e, std::abs(s[c] - v[i*nc_ + c]));
                err[i] = used[i] ? -1 : e;
                emax = std::max(emax, e);
            }
            stats_.maxError = vmax > 0 ? emax/vmax : 0;
            if (emax <= p_.greedyTolerance*vmax || centres.size() == x_.size()) break;
            std::vector<std::size_t> cand(x_.size());
            std::iota(cand.begin(), cand.end(), 0);
            const std::size_t add = std::min<std::size_t>(std::size_t(p_.greedyBatch), x_.size() - centres.size());
            mba::collectively(comm_, [&] {
                std::ostringstream os;
                os << "rbf: the greedy selection needs more than maxPoints " << p_.maxPoints
                   << " centres: with " << centres.size() << " the largest error at the control points is still "
                   << stats_.maxError << " of the largest value, above greedyTolerance " << p_.greedyTolerance
                   << " (raise maxPoints if the memory is there, or greedyTolerance)";
                precondition(long(centres.size() + add) <= p_.maxPoints, os.str());
            });
            std::partial_sort(cand.begin(), cand.begin() + add, cand.end(),
                              [&](std::size_t a, std::size_t b) { return err[a] > err[b] || (err[a] == err[b] && a < b); });
            for (std::size_t k = 0; k < add; ++k) { centres.push_back(cand[k]); used[cand[k]] = 1; }
        }
        stats_.setupSeconds += now() - t0;
        return;
    }
    solve(v);
}

template <int D>
void interpolant<D>::evaluateAt(const double* x, double* out) const
{
    const long m = long(centres_.size()), n = stats_.size;
    if (n == 0) return;
    const double r2scale = r2Scale();
    for (long j = 0; j < m; ++j)
    {
        const double f = kernelAt(x, j, r2scale);
        for (int c = 0; c < nc_; ++c) out[c] += coeff_[std::size_t(c)*n + j]*f;
    }
    if (p_.polynomial)
        for (int c = 0; c < nc_; ++c)
        {
            const double* a = &coeff_[std::size_t(c)*n + m];
            double s = a[0];
            for (int d = 0; d < D; ++d) s += a[1 + d]*(x[d] - lo_[d])/scale_;
            out[c] += s;
        }
}

template <int D>
void interpolant<D>::evaluate(pointsView<D> x, std::vector<double>& out) const
{
    out.assign(x.size*nc_, 0.0);
    for (std::size_t i = 0; i < x.size; ++i) evaluateAt(x[i], &out[i*nc_]);
}

template <int D>
std::vector<double> interpolant<D>::basisAt(pointsView<D> x) const
{
    const long m = long(centres_.size()), n = stats_.size;
    std::vector<double> b(x.size*std::size_t(n));
    const double r2scale = r2Scale();
    for (std::size_t q = 0; q < x.size && n > 0; ++q)
    {
        double* row = &b[q*std::size_t(n)];
        for (long j = 0; j < m; ++j) row[j] = kernelAt(x[q], j, r2scale);
        if (p_.polynomial)
        {
            row[m] = 1;
            for (int d = 0; d < D; ++d) row[m + 1 + d] = (x[q][d] - lo_[d])/scale_;
        }
    }
    return b;
}

template <int D>
void interpolant<D>::evaluate(const std::vector<double>& basis, std::vector<double>& out) const
{
    const std::size_t n = std::size_t(stats_.size), rows = n ? basis.size()/n : 0;
    out.assign(rows*nc_, 0.0);
    // A row read once for every component (at most 3), in four independent
    // sums per component (the row comes from memory: the basis is megabytes)
    for (std::size_t q = 0; q < rows; ++q)
    {
        const double* row = &basis[q*n];
        double s[3][4] = {};
        std::size_t j = 0;
        for (; j + 4 <= n; j += 4)
            for (int c = 0; c < nc_; ++c)
            {
                const double* a = &coeff_[std::size_t(c)*n + j];
                for (int k = 0; k < 4; ++k) s[c][k] += row[j + k]*a[k];
            }
        for (int c = 0; c < nc_; ++c)
        {
            double t = (s[c][0] + s[c][1]) + (s[c][2] + s[c][3]);
            for (std::size_t i = j; i < n; ++i) t += row[i]*coeff_[std::size_t(c)*n + i];
            out[q*nc_ + c] = t;
        }
    }
}

template class interpolant<2>;
template class interpolant<3>;

} // namespace rbf
