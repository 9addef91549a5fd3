// The interface's steps: the checks of the input, the domain, the fit loop
// over the levels, the evaluations and the statistics. The parts they use
// are listed in multilevel.hpp.
#include "multilevel.hpp"
#include "affine.hpp"
#include "collectively.hpp"
#include "flatEvaluator.hpp"
#include "levelApply.hpp"
#include "stencilKernels.hpp"
#include "trendLattice.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>

namespace mba {

// The definition C++14 needs where the key is bound to a reference
constexpr std::uint64_t hashMap::emptyKey;

void params::validate() const
{
    precondition(std::isfinite(tolerance) && tolerance >= 0,
        "mba: tolerance must be a finite number >= 0, got " + std::to_string(tolerance));
    precondition(maxLevels >= 1 && maxLevels <= 30,
        "mba: maxLevels must be in [1, 30], got " + std::to_string(maxLevels));
    precondition(initialGrid >= 1 && initialGrid <= (1 << 20),
        "mba: initialGrid must be in [1, 2^20], got " + std::to_string(initialGrid));
    precondition(std::isfinite(padding) && padding > 0 && padding <= 1,
        "mba: padding must be in (0, 1], got " + std::to_string(padding));
    precondition(bucketTiles >= 1, "mba: bucketTiles must be >= 1, got " + std::to_string(bucketTiles));
}

namespace {

double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

} // namespace

template <int D>
struct multilevel<D>::state
{
    const communicator& comm;           ///< the ranks (the caller's: it outlives the plan)
    params parameters;                  ///< as given (checkInput validates them)
    controlPoints<D> ctrl;              ///< this rank's control points, their masks, in spatial order
    evaluationPoints<D> eval;           ///< this rank's evaluation points, in the sweep's order
    domain<D> dom;                      ///< the lattices' domain (all ranks' points, padded)
    trendLattice<D> trend;              ///< the trend under the affine start (fit with a trend)
    affineFit<D> affine;                ///< the affine start (none unless parameters.affine)
    queryClusters<D> clusters;          ///< this rank's query points in clusters (parallel only)
    std::deque<levelPlan<D>> levels;    ///< the levels planned so far (a fit plans those it needs)
    std::vector<double> residuals;      ///< per control point x component: what the levels so far leave
    levelApplier<D> applier;            ///< a level's apply and its work arrays
    flatEvaluator<D> evaluator;         ///< the evaluation at the planned points
    fitReport report;                   ///< of the last fit
    int readPastMax = -1;               ///< whether an evaluation point reads level maxLevels (-1: not asked yet)

    state(const communicator& c, const params& p, int nc, pointsView<D> control, std::vector<std::uint8_t> mask,
          pointsView<D> evaluation, std::vector<std::uint8_t> evaluationMask)
    :
        comm(c), parameters(p), ctrl(control, nc, std::move(mask)), eval(evaluation, nc, std::move(evaluationMask)),
        applier(comm, dom, ctrl), evaluator(eval, ctrl, dom)
    {}

    void checkInput() const;
    box<D> findDomain(const box<D>* bounds);
    double checkValues(const std::vector<double>& values) const;
    void setTrend(int k, const std::vector<double>& coefficients);
    void startResiduals(const std::vector<double>& values);
    void residualStats(double& maxr, double& rms) const;
    void addLevels(const double* x, double* out, int nLevels) const;
    void storeDeferredCoefficients() const;
};

/// Parameters, component count, mask size and coordinates. Collective.
template <int D>
void multilevel<D>::state::checkInput() const
{
    collectively(comm, [&] {
        parameters.validate();
        const int nc = ctrl.nComponents;
        precondition(nc >= 1 && nc <= 3, "mba: 1 to 3 value components, got " + std::to_string(nc));
        precondition(ctrl.mask.empty() || ctrl.mask.size() == ctrl.x.size*nc,
            "mba: the mask has " + std::to_string(ctrl.mask.size()) + " entries, expected "
            + std::to_string(ctrl.x.size*nc) + " (control points x components)");
        precondition(eval.mask.empty() || eval.mask.size() == eval.x.size*nc,
            "mba: the evaluation mask has " + std::to_string(eval.mask.size()) + " entries, expected "
            + std::to_string(eval.x.size*nc) + " (evaluation points x components)");
        for (std::size_t i = 0; i < ctrl.x.size; ++i)
            for (int d = 0; d < D; ++d)
                if (!std::isfinite(ctrl.x[i][d]))
                    precondition(false, "mba: control point " + std::to_string(i) + " has a non-finite coordinate");
        for (std::size_t i = 0; i < eval.x.size; ++i)
            for (int d = 0; d < D; ++d)
                if (!std::isfinite(eval.x[i][d]))
                    precondition(false, "mba: evaluation point " + std::to_string(i) + " has a non-finite coordinate");
    });
}

namespace {

/// Each of boxes made the bounding box of that box of every rank (one
/// all-gather). Collective.
template <int D>
void boxesOfAllRanks(const communicator& comm, std::vector<box<D>>& boxes)
{
    const std::size_t n = boxes.size();
    std::vector<double> mm(2*D*n);
    for (std::size_t k = 0; k < n; ++k)
        for (int d = 0; d < D; ++d) { mm[2*D*k + d] = boxes[k].lo[d]; mm[2*D*k + D + d] = -boxes[k].hi[d]; }
    const std::vector<double> g = comm.allGatherFixed(mm);
    for (std::size_t at = 0; at < g.size(); at += 2*D*n)
        for (std::size_t k = 0; k < n; ++k)
            for (int d = 0; d < D; ++d)
            {
                boxes[k].lo[d] = std::min(boxes[k].lo[d], g[at + 2*D*k + d]);
                boxes[k].hi[d] = std::max(boxes[k].hi[d], -g[at + 2*D*k + D + d]);
            }
}

} // namespace

/// The domain: the global bounding box of the active control points and
/// the evaluation points (or the given bounds, which must contain it),
/// padded. Returns the active control points' global bounding box.
/// Collective.
template <int D>
box<D> multilevel<D>::state::findDomain(const box<D>* bounds)
{
    std::vector<box<D>> b(2, box<D>::empty());    // control, evaluation points
    for (std::size_t i = 0; i < ctrl.x.size; ++i) if (ctrl.active[i]) b[0].add(ctrl.x[i]);
    for (std::size_t i = 0; i < eval.x.size; ++i) b[1].add(eval.x[i]);
    boxesOfAllRanks(comm, b);
    box<D> all = b[0];
    all.add(b[1]);
    if (bounds)
    {
        collectively(comm, [&] {
            for (int d = 0; d < D; ++d)
                precondition(all.isEmpty() || (bounds->lo[d] <= all.lo[d] && all.hi[d] <= bounds->hi[d]),
                    "mba: the given bounds do not contain all points");
        });
        all = *bounds;
    }
    collectively(comm, [&] { dom = domain<D>::fromBox(all, parameters.initialGrid, parameters.padding); });
    return b[0];
}

template <int D>
multilevel<D>::multilevel(const communicator& comm, const params& p, int nComponents,
                          pointsView<D> control, std::vector<std::uint8_t> mask,
                          pointsView<D> evaluation, const box<D>* bounds)
:
    multilevel(comm, p, nComponents, control, std::move(mask), evaluation, std::vector<std::uint8_t>(), bounds)
{}

template <int D>
multilevel<D>::multilevel(const communicator& comm, const params& p, int nComponents,
                          pointsView<D> control, std::vector<std::uint8_t> mask,
                          pointsView<D> evaluation, std::vector<std::uint8_t> evaluationMask,
                          const box<D>* bounds)
:
    state_(new state(comm, p, nComponents, control, std::move(mask), evaluation, std::move(evaluationMask)))
{
    state& s = self();
    s.checkInput();
    s.ctrl.classify(comm);
    const box<D> controlBox = s.findDomain(bounds);
    precondition(s.ctrl.x.size < (std::size_t(1) << 32) && s.eval.x.size < (std::size_t(1) << 32),
        "mba: at most 2^32 points per rank");
    s.ctrl.arrange(s.dom);
    s.eval.arrange(s.dom);
    if (s.parameters.affine)
    {
        // Centred on the active control points' bounding box (of all ranks:
        // the same on any decomposition), each component's fit about its
        // own points' centroid: where they leave a direction undetermined
        // (all in a plane, on a line, one point), the minimum-norm fit then
        // has no gradient along it, and a translation of them translates
        // the mesh
        const box<D>& b = controlBox;
        point<D> centre;
        double ext = 0;
        for (int d = 0; d < D; ++d)
        {
            centre[d] = b.isEmpty() ? s.dom.lo[d] + 0.5*s.dom.n0[d]*s.dom.h0 : 0.5*(b.lo[d] + b.hi[d]);
            ext = std::max(ext, s.dom.n0[d]*s.dom.h0);
        }
        s.affine = affineFit<D>(comm, nComponents, control, s.ctrl.mask, centre, 0.5*ext);
    }
    s.clusters = clusterQueryPoints<D>(comm, s.ctrl, evaluation);
    s.residuals.assign(control.size*nComponents, 0.0);
}

template <int D>
multilevel<D>::~multilevel() = default;

/// The largest |value| of the constrained components; throws (collectively)
/// on a wrong count or a value that is not finite
template <int D>
double multilevel<D>::state::checkValues(const std::vector<double>& values) const
{
    const int nc = ctrl.nComponents;
    double vmax = 0;
    collectively(comm, [&] {
        precondition(values.size() == ctrl.x.size*nc,
            "mba: " + std::to_string(values.size()) + " control values, expected "
            + std::to_string(ctrl.x.size*nc) + " (control points x components)");
        for (std::size_t i = 0; i < values.size(); ++i)
        {
            if (!(ctrl.mask.empty() || ctrl.mask[i])) continue;
            if (!std::isfinite(values[i]))
                precondition(false, "mba: control value " + std::to_string(i/nc) + " component "
                    + std::to_string(i%nc) + " is not finite");
            vmax = std::max(vmax, std::abs(values[i]));
        }
    });
    return vmax;
}

/// The trend of the next fits (k < 0: none); throws (collectively) on a
/// level out of range, a wrong count or a coefficient that is not finite
template <int D>
void multilevel<D>::state::setTrend(int k, const std::vector<double>& coefficients)
{
    if (k < 0)
    {
        trend = trendLattice<D>();
        return;
    }
    collectively(comm, [&] {
        const indexBox<D> b = trendLattice<D>::nodeBox(dom, k);
        const double n = boxNodes<D>(b)*ctrl.nComponents;
        precondition(double(coefficients.size()) == n,
            "mba: " + std::to_string(coefficients.size()) + " trend coefficients, expected "
            + std::to_string(std::int64_t(n)) + " (level " + std::to_string(k) + " nodes x components)");
        for (std::size_t i = 0; i < coefficients.size(); ++i)
            if (!std::isfinite(coefficients[i]))
                precondition(false, "mba: trend coefficient " + std::to_string(i) + " is not finite");
        trend.level = k;
        trend.box = b;
        trend.phi = coefficients;
    });
}

/// residuals = values minus the trend and the affine start (solved for
/// what the trend leaves first)
template <int D>
void multilevel<D>::state::startResiduals(const std::vector<double>& values)
{
    const int nc = ctrl.nComponents;
    residuals = values;
    if (trend.active())
    {
        for (std::size_t i = 0; i < ctrl.x.size; ++i)
        {
            if (!ctrl.active[i]) continue;
            double g[3] = {0, 0, 0};
            trend.addAt(dom.local0(ctrl.x[i]), nc, g);
            for (int c = 0; c < nc; ++c) residuals[i*nc + c] -= g[c];
        }
    }
    if (!parameters.affine) return;
    affine.solve(comm, ctrl.x, ctrl.mask, residuals);
    for (std::size_t i = 0; i < ctrl.x.size; ++i)
    {
        double g[3] = {0, 0, 0};
        affine.addTo(ctrl.x[i], g);
        for (int c = 0; c < nc; ++c) residuals[i*nc + c] -= g[c];
    }
}

/// The largest and the rms residual over all ranks' constrained components
template <int D>
void multilevel<D>::state::residualStats(double& maxr, double& rms) const
{
    // (four partial maxima and sums: independent chains)
    double m[4] = {0, 0, 0, 0}, s[4] = {0, 0, 0, 0};
    const std::vector<std::uint8_t>& mask = ctrl.mask;
    const bool all = mask.empty();
    const std::size_t nv = ctrl.x.size*ctrl.nComponents;
    for (std::size_t j = 0; j < nv; ++j)
    {
        const double r = all || mask[j] ? residuals[j] : 0.0;
        m[j & 3] = std::max(m[j & 3], std::abs(r));
        s[j & 3] += r*r;
    }
    const double n = all ? double(nv) : double(nv - std::count(mask.begin(), mask.end(), std::uint8_t(0)));
    // one all-gather for the maximum and the sums (added in rank order, as comm.sum)
    maxr = std::max(std::max(m[0], m[1]), std::max(m[2], m[3]));
    double sn[2] = {0, 0};
    const std::vector<double> g = comm.allGatherFixed(std::vector<double>{maxr, (s[0] + s[1]) + (s[2] + s[3]), n});
    for (std::size_t at = 0; at < g.size(); at += 3)
    {
        maxr = std::max(maxr, g[at]);
        sn[0] += g[at + 1];
        sn[1] += g[at + 2];
    }
    rms = sn[1] > 0 ? std::sqrt(sn[0]/sn[1]) : 0.0;
}

template <int D>
const fitReport& multilevel<D>::fit(const std::vector<double>& values)
{
    return fit(values, -1, std::vector<double>());
}

template <int D>
const fitReport& multilevel<D>::fit(const std::vector<double>& values, int trendLevel,
                                   const std::vector<double>& trend)
{
    const double t0 = now();
    state& s = self();
    const double vmax = s.checkValues(values);
    s.setTrend(trendLevel, trend);
    fitReport& rep = s.report;
    rep = fitReport();
    rep.maxValue = s.comm.max(vmax);
    rep.threshold = s.parameters.relative ? s.parameters.tolerance*rep.maxValue : s.parameters.tolerance;
    s.startResiduals(values);
    double maxr, rms;
    s.residualStats(maxr, rms);
    rep.initialMaxResidual = maxr;
    int k = 0;
    while (!(maxr <= rep.threshold) && k < s.parameters.maxLevels)
    {
        if (k == int(s.levels.size()))
        {
            const double t1 = now();
            // Whether a level is read follows from its control points'
            // tiles alone: one that is not is never planned in full
            std::function<bool(const levelPlan<D>&)> isRead;
            if (s.parameters.stopUnread) isRead = [&](const levelPlan<D>& c) { return s.evaluator.reads(c); };
            s.levels.push_back(planLevel<D>(k, s.comm, s.dom, s.ctrl, s.clusters, s.parameters.bucketTiles,
                                            s.parameters.exchange, isRead));
            s.levels.back().stats.planSeconds = now() - t1;
        }
        if (!s.levels[k].read)
        {
            rep.unread = true;
            break;
        }
        const double t1 = now();
        s.applier.apply(s.levels[k], s.residuals);
        s.residualStats(maxr, rms);
        levelStats& ls = s.levels[k].stats;
        ls.maxResidual = maxr;
        ls.rmsResidual = rms;
        ls.seconds = now() - t1;
        ++k;
    }
    // Stopped at maxLevels above the threshold: the fit needs no more
    // levels where none would be read (asked once, from the next level's
    // tiles alone, never planned)
    if (!(maxr <= rep.threshold) && !rep.unread && s.parameters.stopUnread
        && k == s.parameters.maxLevels && k < 30 && k == int(s.levels.size()))
    {
        if (s.readPastMax < 0)
        {
            bool mine = false;
            const std::function<bool(const levelPlan<D>&)> ask = [&](const levelPlan<D>& c)
            {
                mine = s.evaluator.reads(c);
                return false;
            };
            planLevel<D>(k, s.comm, s.dom, s.ctrl, s.clusters, s.parameters.bucketTiles, s.parameters.exchange, ask);
            s.readPastMax = s.comm.max(mine ? 1.0 : 0.0) > 0;
        }
        rep.unread = s.readPastMax == 0;
    }
    rep.levels = k;
    s.evaluator.update(s.levels, k, s.affine, s.trend, s.comm.size());
    rep.maxResidual = maxr;
    rep.rmsResidual = rms;
    rep.converged = maxr <= rep.threshold;
    rep.seconds = now() - t0;
    return rep;
}

/// Adds the affine start, the trend and the first nLevels levels at x, their tiles
/// looked up point by point
template <int D>
void multilevel<D>::state::addLevels(const double* x, double* out, int nLevels) const
{
    const int nc = ctrl.nComponents;
    affine.addTo(x, out);
    const point<D> u0 = dom.local0(x);
    trend.addAt(u0, nc, out);
    stencilTiles<D> tid;
    std::vector<std::uint32_t> scratch;
    for (int k = 0; k < nLevels; ++k)
    {
        const levelPlan<D>& L = levels[k];
        const stencil<D> st = levelStencil<D>(u0, L.scale);
        // No tile here: none at finer levels either (their nodes lie within
        // the stencils of the same control points)
        if (!findTiles(L.view, st, tid)) break;
        forEachLoneOverlap(L, ctrl, st, tid, scratch, [&](std::uint32_t j, double K) {
            for (int c = 0; c < nc; ++c) out[c] += K*L.loneResiduals[j*nc + c];
        });
        for (std::int32_t& id : tid) if (id >= L.storedTiles) id = -1;
        evalStencil(L.phi.data(), nc, tid, st, out);
    }
}

/// Every level's coefficients at every node, for the evaluations that read
/// the whole lattices (a cache filled on demand: see levelPlan::phi)
template <int D>
void multilevel<D>::state::storeDeferredCoefficients() const
{
    for (const levelPlan<D>& L : levels) mba::storeDeferredCoefficients<D>(L, ctrl);
}

template <int D>
void multilevel<D>::evaluate(std::vector<double>& out) const
{
    const state& s = self();
    if (s.evaluator.active())
    {
        s.evaluator.evaluate(s.levels, s.report.levels, out);
        return;
    }
    const int nc = s.ctrl.nComponents;
    out.assign(s.eval.size()*nc, 0.0);
    for (std::size_t q = 0; q < s.eval.size(); ++q)
        s.addLevels(s.eval.x[s.eval.at(q)], &out[s.eval.at(q)*nc], s.report.levels);
}

template <int D>
void multilevel<D>::evaluate(const double* x, double* out) const
{
    const state& s = self();
    if (s.comm.size() != 1)
        throw std::logic_error("mba: evaluation at unplanned points needs the serial communicator");
    s.storeDeferredCoefficients();
    for (int c = 0; c < s.ctrl.nComponents; ++c) out[c] = 0;
    s.addLevels(x, out, s.report.levels);
}

template <int D>
void multilevel<D>::evaluateControl(std::vector<double>& out) const
{
    const state& s = self();
    const int nc = s.ctrl.nComponents;
    s.storeDeferredCoefficients();
    out.assign(s.ctrl.x.size*nc, 0.0);
    for (std::size_t i = 0; i < s.ctrl.x.size; ++i) s.addLevels(s.ctrl.x[i], &out[i*nc], s.report.levels);
}

template <int D>
std::vector<double> multilevel<D>::latticeNodes(int k) const
{
    const domain<D>& dom = self().dom;
    const indexBox<D> b = trendLattice<D>::nodeBox(dom, k);
    const double h = std::ldexp(dom.h0, -k);
    std::vector<double> x;
    x.reserve(std::size_t(boxNodes<D>(b))*D);
    forEachIndex<D>(b, [&](const index<D>& j) {
        for (int d = 0; d < D; ++d) x.push_back(dom.lo[d] + double(j[d] - 1)*h);
    });
    return x;
}

template <int D>
const domain<D>& multilevel<D>::dom() const
{
    return self().dom;
}

template <int D>
const fitReport& multilevel<D>::report() const
{
    return self().report;
}

template <int D>
int multilevel<D>::nComponents() const
{
    return self().ctrl.nComponents;
}

template <int D>
std::vector<levelStats> multilevel<D>::stats() const
{
    std::vector<levelStats> s;
    for (const levelPlan<D>& L : self().levels) s.push_back(L.stats);
    return s;
}

template <int D>
std::int64_t multilevel<D>::bytes() const
{
    const state& s = self();
    std::int64_t b = std::int64_t((s.residuals.capacity() + s.trend.phi.capacity())*sizeof(double))
        + s.ctrl.bytes() + s.eval.bytes()
        + s.applier.bytes() + s.evaluator.bytes();
    for (const levelPlan<D>& L : s.levels) b += L.stats.bytes;
    return b;
}

template <int D>
std::int64_t multilevel<D>::gatherAllBytes() const
{
    const state& s = self();
    std::int64_t mine = 0;
    for (auto a : s.ctrl.active) mine += a;
    return (s.ctrl.nActiveGlobal - mine)*(D + s.ctrl.nComponents)*std::int64_t(sizeof(double));
}

template class multilevel<2>;
template class multilevel<3>;

} // namespace mba
