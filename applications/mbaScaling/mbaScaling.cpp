// mbaScaling: per-rank communication and work of the distributed multilevel
// B-spline core on the twisted cube, on simulated ranks (OpenFOAM-free).
//
//   mbaScaling [--n N] [--ranks "P1 P2 ..."] [--decomposition simple|hierarchical|columns]
//              [--levels] [--steps S] [--lower-bound] [--exchange automatic|direct|chunked|tree]
//              [--control owner|balanced|local] [--replay [--cold]] [--per-rank]
//
// The mesh is the twisted cube of tutorials/twistedCube: the unit cube in N^3
// cells (default 100: 1M cells), its (N+1)^3 points. The control points are
// those of the fixed bottom and of the top, turned by 0.5 rad about the
// vertical axis and indented by a sphere (radius 0.3, depth 0.15): 3
// components each. The sides and the interior are evaluated. The cells are
// split as decomposePar splits this mesh: `simple` in P slabs along x (n (P 1
// 1)), `hierarchical` in a x b x c boxes (a >= b >= c, as near equal as P
// allows), `columns` in a x b x 1 (hierarchical, n (a b 1): every rank holds
// its share of the top and the bottom). A point on a processor boundary is held by every rank whose cells
// it touches (each evaluates it); a control point belongs to the lowest of
// them, as the motion solver counts it. --control balanced instead hands the
// control points to the ranks in equal blocks whatever their cells (the
// bottom's to the first half of the ranks, the top's to the second, each
// plane in a x b blocks as `columns` splits P/2; even rank counts): what
// the fit costs when the control points are spread evenly over the ranks
// (a rank's cells' points of the top and bottom are then another rank's
// control points: prescribed, not evaluated, as in the motion solver).
// --control local hands half of a wall box's control points to the box next
// to it along z (boxes of at least three parts along z; otherwise as owner):
// the box at the bottom keeps the points of its cells in the lower half of
// its x range and hands the others to the box above it, the box at the top
// to the box below it: the control points spread over twice as many ranks,
// each next to the rank whose cells hold them.
//
// Per rank count: the plan and a first fit, then a step measured (a fit
// through the plan with new values, and the evaluation; the median of --steps, whose CPU times
// can hold a stall of the kernel's, such as a huge page's compaction). Per rank: its control
// and evaluation points, its neighbours (ranks it shares points with), what it
// receives point-to-point in the step (bytes, messages), what the step's
// collectives cost it, and the CPU time of its fit and evaluation (thread CPU
// time: each simulated rank's own work, whatever the cores; less the time in
// the simulated communicator, which a network replaces). Prints a table per
// rank count and one RESULT line each (key=value), which benchmarks/scaling
// reads; --levels adds the per-level exchange of the rank that receives most;
// --lower-bound the least any exchange of values per level could receive
// (lowerBoundBytes), against the share (with --levels, per level too);
// --exchange the levels' exchange (params::exchange; default automatic, the
// motion solver's).
//
// --replay measures the ranks' fit and evaluation again, each rank alone:
// the simulated ranks record what each rank's communication returned, and
// each rank then runs once more by itself in the main thread, its
// communicator handing it those results in the same order (the algorithm is
// deterministic: each all-gather checks that the rank's own part is what it
// was, and the rank's evaluated values must come out the same bit for bit;
// a departure stops the program with an error). Its work is then measured
// as on a core of its own, as a real rank runs: on the simulated ranks many
// threads share two cores, and each finds its caches emptied by the others
// whenever it waits for them (every exchange and all-gather), and their
// allocations contend. The plan and the figures of the communication are
// the simulated run's; the RESULT line adds the simulated ranks' work
// (simulated_work_max, _mean).
//
// --cold (with --replay) empties the caches before each replayed step:
// the rank streams through a buffer twice the size of the last-level cache
// (sysconf; at least 64 MiB), outside the measured time. The motion solver's
// step follows the flow solver's, which has gone through all of its fields
// and left little of the morpher's data in the caches; without it a replayed
// rank whose data are a few MB finds them in the cache from its previous
// step, as a rank on a node whose cores share that cache would not.
//
// --per-rank adds a line per rank: its control and evaluated points, and its
// fit and evaluation work (with --replay, measured alone): where the work
// of a decomposition sits.

#include "multilevel.hpp"
#include "recordedCommunicators.hpp"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <numeric>
#include <set>
#include <sstream>
#include <string>

#include <unistd.h>

using namespace mba;

namespace {

struct options
{
    long n = 100;
    std::vector<int> ranks{1, 2, 4, 8, 16, 32, 64};
    std::string decomposition = "simple";
    bool levels = false;
    bool lowerBound = false;
    int steps = 1;
    params::exchangeMode exchange = params::exchangeMode::automatic;
    std::string exchangeName = "automatic";   ///< as given, for the RESULT line
    std::string control = "owner";   ///< --control: owner, balanced or local
    bool replay = false;     ///< --replay
    bool perRank = false;    ///< --per-rank
    bool cold = false;       ///< --cold
};

[[noreturn]] void usage(const std::string& msg)
{
    // (--help: the usage alone, on standard output, exit status 0)
    std::ostream& os = msg.empty() ? std::cout : std::cerr;
    if (!msg.empty()) os << "mbaScaling: " << msg << "\n";
    os <<
        "usage: mbaScaling [--n N] [--ranks \"P1 P2 ...\"] [--decomposition simple|hierarchical|columns]\n"
        "                  [--levels] [--steps S] [--lower-bound] [--exchange automatic|direct|chunked|tree]\n"
        "                  [--control owner|balanced|local] [--replay [--cold]] [--per-rank]\n";
    std::exit(msg.empty() ? 0 : 2);
}

/// Parts per direction: (P 1 1), the most even a >= b >= c with a b c = P,
/// or the most even a >= b with a b = P (columns: c = 1)
std::array<int, 3> parts(int P, const std::string& how)
{
    if (how == "simple") return {P, 1, 1};
    std::array<int, 3> best{P, 1, 1};
    for (int c = 1; how == "columns" ? c == 1 : c*c*c <= P; ++c)
    {
        if (P % c) continue;
        for (int b = c; b*b <= P/c; ++b)
        {
            if ((P/c) % b) continue;
            const int a = P/c/b;
            if (a - c < best[0] - best[2]) best = {a, b, c};
        }
    }
    return best;
}

options parse(int argc, char** argv)
{
    options o;
    for (int i = 1; i < argc; ++i)
    {
        const std::string a = argv[i];
        if (a == "--help" || a == "-h" || a == "-help") usage("");
        auto val = [&]() -> std::string {
            if (i + 1 >= argc) usage("missing value for " + a);
            return argv[++i];
        };
        try
        {
            if (a == "--n") o.n = std::stol(val());
            else if (a == "--ranks")
            {
                o.ranks.clear();
                std::istringstream is(val());
                for (int p; is >> p;) o.ranks.push_back(p);
            }
            else if (a == "--decomposition") o.decomposition = val();
            else if (a == "--levels") o.levels = true;
            else if (a == "--lower-bound") o.lowerBound = true;
            else if (a == "--replay") o.replay = true;
            else if (a == "--per-rank") o.perRank = true;
            else if (a == "--cold") o.cold = true;
            else if (a == "--steps") o.steps = std::stoi(val());
            else if (a == "--exchange")
            {
                const std::string e = val();
                o.exchangeName = e;
                if (e == "automatic") o.exchange = params::exchangeMode::automatic;
                else if (e == "direct") o.exchange = params::exchangeMode::direct;
                else if (e == "chunked") o.exchange = params::exchangeMode::chunked;
                else if (e == "tree") o.exchange = params::exchangeMode::tree;
                else usage("--exchange must be automatic, direct, chunked or tree");
            }
            else if (a == "--control")
            {
                o.control = val();
                if (o.control != "owner" && o.control != "balanced" && o.control != "local")
                    usage("--control must be owner, balanced or local");
            }
            else usage("unknown option " + a);
        }
        catch (const std::logic_error&) { usage("bad value for " + a); }
    }
    if (o.decomposition != "simple" && o.decomposition != "hierarchical" && o.decomposition != "columns")
        usage("--decomposition must be simple, hierarchical or columns");
    if (o.n < 2) usage("--n must be at least 2");
    if (o.steps < 1) usage("--steps must be at least 1");
    if (o.control != "owner" && o.lowerBound) usage("--lower-bound counts the cells' owners: only with --control owner");
    for (int p : o.ranks)
    {
        if (p < 1) usage("rank counts must be positive");
        if (o.control == "balanced" && p % 2) usage("--control balanced needs even rank counts");
        for (int m : parts(p, o.decomposition))
            if (m > o.n) usage("rank count " + std::to_string(p) + " splits a direction into more parts than cells");
    }
    if (o.ranks.empty()) usage("--ranks needs at least one rank count");
    if (o.cold && !o.replay) usage("--cold empties the caches before each replayed step: only with --replay");
    return o;
}

/// Empties the caches (--cold): reads one byte a cache line of a
/// buffer twice the last-level cache's size, at least 64 MiB
void evictCaches()
{
    static std::vector<unsigned char> buffer;
    if (buffer.empty())
    {
        long llc = 0;
#ifdef _SC_LEVEL3_CACHE_SIZE
        llc = std::max(sysconf(_SC_LEVEL3_CACHE_SIZE), sysconf(_SC_LEVEL2_CACHE_SIZE));
#endif
        buffer.assign(std::size_t(std::max(2*llc, 64L << 20)), 1);
    }
    unsigned sum = 0;
    for (std::size_t i = 0; i < buffer.size(); i += 64) sum += buffer[i];
    static volatile unsigned sink;
    sink = sum;
}

/// The twisted cube's top and bottom at t = 1: displacement of the point x
point<3> displacement(const point<3>& x)
{
    point<3> d{0, 0, 0};
    if (x[2] < 0.5) return d;
    const double a = 0.5, c = std::cos(a), s = std::sin(a);
    const double dx = x[0] - 0.5, dy = x[1] - 0.5;
    point<3> y{0.5 + c*dx - s*dy, 0.5 + s*dx + c*dy, x[2]};
    // the sphere (centre 1.15 above the axis, radius 0.3) pushes points down onto it
    const double rx = y[0] - 0.5, ry = y[1] - 0.5, r2 = rx*rx + ry*ry;
    if (r2 < 0.09) y[2] = std::min(y[2], 1.15 - std::sqrt(0.09 - r2));
    for (int k = 0; k < 3; ++k) d[k] = y[k] - x[k];
    return d;
}

/// The least a rank must receive per step (bytes) for any exchange of values
/// per level, the lattice's or the control points' (this one's or another):
/// per level, the nodes its query points' stencils touch that some other
/// rank's control point touches (it cannot form their values alone), or
/// else those other ranks' control points that touch them, whichever are
/// fewer, 3 values of 8 bytes each. The control points are the grid's on the
/// planes z = 0 and z = 1; owner(i, j, k) is the rank holding grid point (i,
/// j, k) that counts it.
template <class Owner>
std::vector<double> lowerBoundBytes(const domain<3>& dom, int levels, long n, const std::vector<point<3>>& query,
                                    int me, Owner owner)
{
    std::vector<double> total(levels, 0.0);
    for (int k = 0; k < levels; ++k)
    {
        const double s = std::ldexp(1.0, k);
        // a grid coordinate's stencil base at this level, per direction
        auto base = [&](int d, long i) {
            point<3> x{0.5, 0.5, 0.5};
            x[d] = double(i)/n;
            return std::int64_t(dom.local0(x.data())[d]*s);
        };
        std::array<std::vector<std::int64_t>, 3> gb;
        for (int d = 0; d < 3; ++d) for (long i = 0; i <= n; ++i) gb[d].push_back(base(d, i));
        const std::int64_t planeBase[2] = {gb[2][0], gb[2][n]};
        const std::int64_t nx = gb[0][n] + 4, ny = gb[1][n] + 4;
        // the node layers (z) the planes' points touch, each once
        std::vector<std::int64_t> zs;
        for (int p = 0; p < 2; ++p) for (int l = 0; l < 4; ++l) zs.push_back(planeBase[p] + l);
        std::sort(zs.begin(), zs.end());
        zs.erase(std::unique(zs.begin(), zs.end()), zs.end());
        const std::int64_t nz = std::int64_t(zs.size());
        // the query points' nodes on those layers: (layer, y, x)
        std::vector<std::uint8_t> needed(std::size_t(nz*nx*ny), 0);
        std::int64_t last[3] = {-1, -1, -1};
        for (const point<3>& x : query)
        {
            point<3> u = dom.local0(x.data());
            for (double& c : u) c *= s;
            const std::int64_t b[3] = {std::int64_t(u[0]), std::int64_t(u[1]), std::int64_t(u[2])};
            if (b[0] == last[0] && b[1] == last[1] && b[2] == last[2]) continue;
            std::copy(b, b + 3, last);
            for (std::int64_t z = 0; z < nz; ++z)
            {
                if (zs[z] < b[2] || zs[z] > b[2] + 3) continue;
                for (std::int64_t a1 = b[1]; a1 <= b[1] + 3; ++a1)
                    for (std::int64_t a0 = b[0]; a0 <= b[0] + 3; ++a0)
                        needed[std::size_t((z*ny + a1)*nx + a0)] = 1;
            }
        }
        // a needed node is remote when another rank's control point touches
        // it (those points marked)
        std::vector<std::uint8_t> remotePoint(std::size_t(2*(n + 1)*(n + 1)), 0);
        double nodes = 0;
        auto range = [&](int d, std::int64_t a, long& i0, long& i1) {
            // grid indices i with base in [a - 3, a]
            const auto& g = gb[d];
            i0 = long(std::lower_bound(g.begin(), g.end(), a - 3) - g.begin());
            i1 = long(std::upper_bound(g.begin(), g.end(), a) - g.begin()) - 1;
        };
        for (std::int64_t z = 0; z < nz; ++z)
            for (std::int64_t a1 = 0; a1 < ny; ++a1)
                for (std::int64_t a0 = 0; a0 < nx; ++a0)
                {
                    if (!needed[std::size_t((z*ny + a1)*nx + a0)]) continue;
                    long i0, i1, j0, j1;
                    range(0, a0, i0, i1);
                    range(1, a1, j0, j1);
                    bool remote = false;
                    for (int p = 0; p < 2; ++p)
                    {
                        if (zs[z] < planeBase[p] || zs[z] > planeBase[p] + 3) continue;
                        for (long j = j0; j <= j1; ++j)
                            for (long i = i0; i <= i1; ++i)
                                if (owner(i, j, p ? n : 0) != me)
                                {
                                    remote = true;
                                    remotePoint[std::size_t((p*(n + 1) + j)*(n + 1) + i)] = 1;
                                }
                    }
                    nodes += remote;
                }
        double points = 0;
        for (const std::uint8_t r : remotePoint) points += r;
        total[k] = 24*std::min(nodes, points);
    }
    return total;
}

/// One rank's figures of the measured step
struct rankFigures
{
    double control = 0, evaluation = 0, neighbours = 0;
    double bytes = 0, messages = 0, collectiveBytes = 0, gathers = 0, exchanges = 0;
    double fitCpu = 0, evalCpu = 0, planCpu = 0;
    double simulatedWork = 0;   ///< --replay: fitCpu + evalCpu as the simulated ranks measured them
    std::uint64_t valuesHash = 0;     ///< of the last evaluation's values (the replay must give the same bits)
    std::vector<double> lowerBound;   ///< lowerBoundBytes, per level
};

/// FNV-1a of the bytes of v
std::uint64_t hashOf(const std::vector<double>& v)
{
    std::uint64_t h = 14695981039346656037ull;
    const unsigned char* b = reinterpret_cast<const unsigned char*>(v.data());
    for (std::size_t i = 0; i < v.size()*sizeof(double); ++i) h = (h ^ b[i])*1099511628211ull;
    return h;
}

/// The median of v (the mean of the middle two where even)
double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    const std::size_t h = v.size()/2;
    return v.size() % 2 ? v[h] : 0.5*(v[h - 1] + v[h]);
}

/// First index of part p of n cells in m parts, and the point range of the part
long first(int p, long n, int m) { return long(p)*n/m; }

struct rankResult
{
    std::vector<rankFigures> ranks;
    std::vector<levelStats> busiestLevels;   ///< the levels of the rank that receives most
    std::vector<double> busiestLeast;        ///< its lowerBoundBytes per level (--lower-bound)
    int levels = 0;
    double maxResidual = 0;
};

rankResult runRanks(const options& o, int P)
{
    const std::array<int, 3> m = parts(P, o.decomposition);
    const long n = o.n;
    params prm;   // the motion solver's defaults, and as it does,
    prm.stopUnread = true;   // no level that no evaluated point reads
    prm.exchange = o.exchange;
    rankResult res;
    res.ranks.resize(P);
    std::mutex mtx;
    // rank comm.rank(): its points, the plan, the measured steps (replayed:
    // its figures only)
    auto runRank = [&](const timedCommunicator& comm, bool replayed) {
        const int r = comm.rank();
        const std::array<int, 3> pr{r % m[0], (r/m[0]) % m[1], r/(m[0]*m[1])};
        std::array<long, 3> lo, hi;
        for (int d = 0; d < 3; ++d) { lo[d] = first(pr[d], n, m[d]); hi[d] = first(pr[d] + 1, n, m[d]); }
        // the lowest rank holding grid point (i, j, k): per direction the
        // first part whose points [first(p), first(p + 1)] reach the index
        auto owner = [&](long i, long j, long k) {
            const long idx[3] = {i, j, k};
            int q[3];
            for (int d = 0; d < 3; ++d)
            {
                q[d] = int(std::min<long>(m[d] - 1, idx[d]*m[d]/n));
                while (q[d] > 0 && first(q[d], n, m[d]) >= idx[d]) --q[d];
                while (first(q[d] + 1, n, m[d]) < idx[d]) ++q[d];
            }
            return q[0] + m[0]*(q[1] + m[1]*q[2]);
        };
        std::vector<point<3>> ctrl, eval;
        std::vector<double> v1, v2;
        auto addControl = [&](const point<3>& x) {
            ctrl.push_back(x);
            const point<3> d = displacement(x);
            for (int c = 0; c < 3; ++c) { v1.push_back(0.5*d[c]); v2.push_back(d[c]); }
        };
        // the rank that fits face point (i, j, k), as --control assigns it
        const std::array<int, 3> bm = parts(std::max(1, P/2), "columns");
        auto fitter = [&](long i, long j, long k) {
            if (o.control == "balanced")
            {
                // plane p's points (bottom, top) to ranks p P/2 ... (p + 1)
                // P/2 - 1, in a x b blocks as `columns` splits P/2
                const long a = std::min<long>(bm[0] - 1, i*bm[0]/(n + 1));
                const long b = std::min<long>(bm[1] - 1, j*bm[1]/(n + 1));
                return int((k == n)*(P/2) + a + bm[0]*b);
            }
            const int q = owner(i, j, k);
            if (o.control == "owner" || m[2] <= 2) return q;
            // local: a wall box keeps its points in the lower half of its x
            // range, the box next to it along z takes the others
            const int qx = q % m[0], qy = (q/m[0]) % m[1], qz = q/(m[0]*m[1]);
            const long a = first(qx, n, m[0]), b = first(qx + 1, n, m[0]);
            return 2*(i - a) > b - a ? qx + m[0]*(qy + m[1]*(qz == 0 ? 1 : qz - 1)) : q;
        };
        for (const long k : {0L, n})
            for (long j = 0; j <= n; ++j)
                for (long i = 0; i <= n; ++i)
                    if (fitter(i, j, k) == r) addControl(point<3>{double(i)/n, double(j)/n, double(k)/n});
        for (long k = std::max(lo[2], 1L); k <= std::min(hi[2], n - 1); ++k)
            for (long j = lo[1]; j <= hi[1]; ++j)
                for (long i = lo[0]; i <= hi[0]; ++i)
                    eval.push_back(point<3>{double(i)/n, double(j)/n, double(k)/n});
        std::set<int> nb;
        for (int q = 0; q < P; ++q)
        {
            const std::array<int, 3> pq{q % m[0], (q/m[0]) % m[1], q/(m[0]*m[1])};
            bool touch = q != r;
            for (int d = 0; d < 3; ++d) touch = touch && std::abs(pq[d] - pr[d]) <= 1;
            if (touch) nb.insert(q);
        }

        rankFigures f;
        f.control = double(ctrl.size());
        f.evaluation = double(eval.size());
        f.neighbours = double(nb.size());
        double t = threadSeconds();
        multilevel<3> mba(comm, prm, 3, pointsView<3>(ctrl.empty() ? nullptr : ctrl[0].data(), ctrl.size()), {},
                          pointsView<3>(eval.empty() ? nullptr : eval[0].data(), eval.size()));
        mba.fit(v1);
        std::vector<double> out;
        mba.evaluate(out);
        f.planCpu = threadSeconds() - t;

        // the step: a fit through the plan, the evaluation (the median of --steps)
        const trafficStats before = comm.traffic();
        const long gathers0 = comm.gathers(), exchanges0 = comm.exchanges();
        std::vector<double> fitSteps, evalSteps;
        for (int step = 0; step < o.steps; ++step)
        {
            if (replayed && o.cold) evictCaches();
            double c = comm.seconds();
            t = threadSeconds();
            mba.fit(step % 2 ? v1 : v2);
            fitSteps.push_back(threadSeconds() - t - (comm.seconds() - c));
            c = comm.seconds();
            t = threadSeconds();
            mba.evaluate(out);
            evalSteps.push_back(threadSeconds() - t - (comm.seconds() - c));
        }
        f.fitCpu = median(fitSteps);
        f.evalCpu = median(evalSteps);
        const fitReport& rep = mba.report();
        if (P > 1 && o.lowerBound && !replayed)
        {
            std::vector<point<3>> query(ctrl);
            query.insert(query.end(), eval.begin(), eval.end());
            f.lowerBound = lowerBoundBytes(mba.dom(), rep.levels, n, query, r, owner);
        }
        const trafficStats after = comm.traffic();
        f.bytes = double(after.bytesReceived - before.bytesReceived)/o.steps;
        f.messages = double(after.messagesReceived - before.messagesReceived)/o.steps;
        f.collectiveBytes = double(after.collectiveBytes - before.collectiveBytes)/o.steps;
        f.gathers = double(comm.gathers() - gathers0)/o.steps;
        f.exchanges = double(comm.exchanges() - exchanges0)/o.steps;
        if (o.replay) f.valuesHash = hashOf(out);
        if (replayed) return f;

        std::lock_guard<std::mutex> lock(mtx);
        res.ranks[r] = f;
        res.levels = rep.levels;
        res.maxResidual = rep.maxResidual;
        const bool busiest = std::none_of(res.ranks.begin(), res.ranks.end(),
                                          [&](const rankFigures& g) { return g.bytes > f.bytes; });
        if (busiest) { res.busiestLevels = mba.stats(); res.busiestLeast = f.lowerBound; }
        return f;
    };
    std::vector<callLog> logs(o.replay ? P : 0);
    runSimulated(P, [&](const communicator& simulated) {
        runRank(timedCommunicator(simulated, o.replay ? &logs[simulated.rank()] : nullptr), false);
    });
    for (int r = 0; r < P && o.replay; ++r)
    {
        const replayCommunicator alone(r, P, logs[r]);
        const rankFigures f = runRank(timedCommunicator(alone), true);
        if (logs[r].next != logs[r].calls.size())
            throw std::logic_error("mbaScaling: the replay makes fewer calls than the run");
        if (f.valuesHash != res.ranks[r].valuesHash)
            throw std::logic_error("mbaScaling: the replay's values differ from the run's");
        res.ranks[r].simulatedWork = res.ranks[r].fitCpu + res.ranks[r].evalCpu;
        res.ranks[r].fitCpu = f.fitCpu;
        res.ranks[r].evalCpu = f.evalCpu;
        res.ranks[r].planCpu = f.planCpu;
        std::vector<std::vector<bytes>>().swap(logs[r].calls);
    }
    return res;
}

struct summary
{
    double max = 0, mean = 0;
};

template <class F>
summary over(const std::vector<rankFigures>& v, F get)
{
    summary s;
    for (const auto& f : v) { s.max = std::max(s.max, get(f)); s.mean += get(f)/double(v.size()); }
    return s;
}

} // namespace

int main(int argc, char** argv)
{
    const options o = parse(argc, argv);
#ifdef __GLIBC__
    // Large arrays always in fresh mappings: glibc raises this threshold as
    // such arrays are freed, and later ones (another rank count's, the
    // replay's) would then come from the heap, and run slower (8M cells on
    // one rank: the fit 0.16 s in the first run, 0.20 s in the replay)
    mallopt(M_MMAP_THRESHOLD, 128*1024);
#endif
    const long n = o.n;
    const long nControl = 2*(n + 1)*(n + 1);
    std::printf("mbaScaling: twisted cube, %ld^3 cells, %ld control points (top and bottom), %ld evaluated points, "
                "decomposition %s, control points %s\n", n, nControl,
                (n + 1)*(n + 1)*(n + 1) - nControl,
                o.decomposition.c_str(), o.control == "balanced" ? "in balanced blocks (--control balanced)"
                : o.control == "local" ? "shared by the wall boxes with the boxes next to them (--control local)"
                : "of their cells' ranks");
    std::printf("per step (a fit through the plan and the evaluation); share: 48 bytes per control point of the "
                "rank's mean share of the boundary\n\n");
    std::printf("%5s %9s %8s %8s %11s %11s %8s %6s %6s %5s %9s %9s %9s %9s %8s\n", "ranks", "parts", "ctrl max",
                "nbrs max", "recv max B", "recv mean B", "max/shr", "msg mx", "msg mn", "lvls", "fit cpu mx",
                "fit mean", "eval mx", "eval mean", "imbal");
    try
    {
        for (const int P : o.ranks)
        {
            const rankResult res = runRanks(o, P);
            const std::vector<rankFigures>& v = res.ranks;
            const std::array<int, 3> m = parts(P, o.decomposition);
            const summary ctrl = over(v, [](const rankFigures& f) { return f.control; });
            const summary eval = over(v, [](const rankFigures& f) { return f.evaluation; });
            const summary nb = over(v, [](const rankFigures& f) { return f.neighbours; });
            const summary bytes = over(v, [](const rankFigures& f) { return f.bytes; });
            const summary msgs = over(v, [](const rankFigures& f) { return f.messages; });
            const summary coll = over(v, [](const rankFigures& f) { return f.collectiveBytes; });
            const summary gathers = over(v, [](const rankFigures& f) { return f.gathers; });
            const summary exchanges = over(v, [](const rankFigures& f) { return f.exchanges; });
            const summary fit = over(v, [](const rankFigures& f) { return f.fitCpu; });
            const summary ev = over(v, [](const rankFigures& f) { return f.evalCpu; });
            const summary work = over(v, [](const rankFigures& f) { return f.fitCpu + f.evalCpu; });
            const summary plan = over(v, [](const rankFigures& f) { return f.planCpu; });
            const summary simulated = over(v, [](const rankFigures& f) { return f.simulatedWork; });
            const summary bound = over(v, [](const rankFigures& f) {
                return std::accumulate(f.lowerBound.begin(), f.lowerBound.end(), 0.0);
            });
            // messages per neighbour and level: the bound the exchange keeps
            const summary perNb = over(v, [&](const rankFigures& f) {
                return f.neighbours > 0 ? f.messages/(f.neighbours*res.levels) : 0.0;
            });
            const double share = 48.0*double(nControl)/P;
            const std::string pstr = std::to_string(m[0]) + "x" + std::to_string(m[1]) + "x" + std::to_string(m[2]);
            std::printf("%5d %9s %8.0f %8.0f %11.0f %11.0f %8.2f %6.0f %6.1f %5d %9.4f %9.4f %9.4f %9.4f %8.2f\n",
                        P, pstr.c_str(), ctrl.max, nb.max, bytes.max, bytes.mean, bytes.max/share, msgs.max,
                        msgs.mean, res.levels, fit.max, fit.mean, ev.max, ev.mean, work.max/work.mean);
            std::printf("RESULT n=%ld decomposition=%s exchange=%s assignment=%s ranks=%d parts=%s levels=%d control=%ld ctrl_max=%.0f "
                        "ctrl_mean=%.1f eval_max=%.0f eval_mean=%.1f neighbours_max=%.0f recv_bytes_max=%.0f "
                        "recv_bytes_mean=%.1f share_bytes=%.1f messages_max=%.0f messages_mean=%.2f "
                        "messages_per_neighbour_level_max=%.3f collective_bytes=%.0f all_gathers=%.0f exchanges=%.0f "
                        "fit_cpu_max=%.6f "
                        "fit_cpu_mean=%.6f eval_cpu_max=%.6f eval_cpu_mean=%.6f work_max=%.6f work_mean=%.6f "
                        "plan_cpu_max=%.4f max_residual=%.17g lower_bound_max=%.0f work_measured=%s caches=%s%s\n",
                        n, o.decomposition.c_str(), o.exchangeName.c_str(), o.control.c_str(), P, pstr.c_str(), res.levels, nControl, ctrl.max, ctrl.mean,
                        eval.max, eval.mean, nb.max, bytes.max, bytes.mean, share, msgs.max, msgs.mean, perNb.max,
                        coll.max, gathers.max, exchanges.max, fit.max, fit.mean, ev.max, ev.mean, work.max, work.mean, plan.max,
                        res.maxResidual, bound.max, o.replay ? "alone" : "simulated", o.cold ? "cold" : "warm",
                        o.replay ? (" simulated_work_max=" + std::to_string(simulated.max) + " simulated_work_mean="
                                    + std::to_string(simulated.mean)).c_str() : "");
            if (o.lowerBound && P > 1)
                std::printf("  least any exchange of values per level could make the busiest rank receive: %.0f bytes, "
                            "%.2f x the share\n", bound.max, bound.max/share);
            if (o.levels)
            {
                std::printf("  levels of the rank receiving most: level, exchange, tiles received, ghosts received, "
                            "messages, bytes received, own tiles, view tiles, apply s, lone points%s\n",
                            o.lowerBound ? ", least bytes possible" : "");
                for (const levelStats& s : res.busiestLevels)
                    std::printf("  %5d %8s %8lld %8lld %4lld %10lld %8lld %8lld %9.6f %8lld%s\n", s.level,
                                s.separated ? "separate" : s.tree ? "tree" : s.chunked ? "chunked" : "direct",
                                static_cast<long long>(s.tilesReceived),
                                static_cast<long long>(s.ghostsReceived), static_cast<long long>(s.messagesReceived),
                                static_cast<long long>(s.bytesReceivedPerApply), static_cast<long long>(s.ownTiles),
                                static_cast<long long>(s.viewTiles), s.seconds,
                                static_cast<long long>(s.lonePoints),
                                s.level < int(res.busiestLeast.size())
                                    ? (" " + std::to_string(std::llround(res.busiestLeast[s.level]))).c_str() : "");
            }
            if (o.perRank)
            {
                std::printf("  per rank: rank, control points, evaluated points, fit s, evaluation s\n");
                for (int r = 0; r < P; ++r)
                    std::printf("  %5d %8.0f %8.0f %9.6f %9.6f\n", r, v[r].control, v[r].evaluation, v[r].fitCpu,
                                v[r].evalCpu);
            }
            std::fflush(stdout);
        }
    }
    catch (const std::exception& e)
    {
        std::cerr << "mbaScaling: error: " << e.what() << std::endl;
        return 1;
    }
    return 0;
}
