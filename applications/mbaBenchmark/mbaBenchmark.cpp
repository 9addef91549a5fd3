// mbaBenchmark: fit, apply and evaluation cost of the multilevel B-spline core
// on scattered data (OpenFOAM-free).
//
//   mbaBenchmark [--case surface|volume] [--k K] [--n N] [--eval M]
//                [--tolerance T] [--max-levels L] [--initial-grid G]
//                [--seed S] [--dim 2|3] [--ranks R] [--no-affine]
//                [--method mba|rbf] [--shape C]
//
// surface: k x k points on each face of the unit cube (N = 6k^2; in 2D k points
// on each edge of the unit square), volume: N random points in the unit cube;
// both evaluated at M random interior points. The control values are a smooth
// field with a sharp Gaussian bump. With --ranks R > 1 the points are split into
// R slabs along x and the distributed algorithm runs on R simulated ranks.
// Prints the sizes, times and statistics, and ends with one key=value line.

#include "multilevel.hpp"
#include "rbfInterpolant.hpp"

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <mutex>
#include <random>
#include <string>

using namespace mba;

namespace {

struct options
{
    std::string kase = "surface";
    long k = 100, n = 60000, eval = 1000000;
    double tolerance = 1e-8;
    int maxLevels = 16, initialGrid = 1, dim = 3, ranks = 1;
    unsigned seed = 1;
    bool affine = true;
    std::string method = "mba";
    double shape = 0.1;
};

[[noreturn]] void usage(const std::string& msg)
{
    // (--help: the usage alone, on standard output, exit status 0)
    std::ostream& os = msg.empty() ? std::cout : std::cerr;
    if (!msg.empty()) os << "mbaBenchmark: " << msg << "\n";
    os <<
        "usage: mbaBenchmark [--case surface|volume] [--k K] [--n N] [--eval M] [--tolerance T]\n"
        "                    [--max-levels L] [--initial-grid G] [--seed S] [--dim 2|3] [--ranks R]\n"
        "                    [--no-affine] [--method mba|rbf] [--shape C]\n";
    std::exit(msg.empty() ? 0 : 2);
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
            if (a == "--case") o.kase = val();
            else if (a == "--k") o.k = std::stol(val());
            else if (a == "--n") o.n = std::stol(val());
            else if (a == "--eval") o.eval = std::stol(val());
            else if (a == "--tolerance") o.tolerance = std::stod(val());
            else if (a == "--max-levels") o.maxLevels = std::stoi(val());
            else if (a == "--initial-grid") o.initialGrid = std::stoi(val());
            else if (a == "--seed") o.seed = unsigned(std::stoul(val()));
            else if (a == "--dim") o.dim = std::stoi(val());
            else if (a == "--ranks") o.ranks = std::stoi(val());
            else if (a == "--no-affine") o.affine = false;
            else if (a == "--method") o.method = val();
            else if (a == "--shape") o.shape = std::stod(val());
            else usage("unknown option " + a);
        }
        catch (const std::logic_error&) { usage("bad value for " + a); }
    }
    if (o.kase != "surface" && o.kase != "volume") usage("--case must be surface or volume");
    if (o.dim != 2 && o.dim != 3) usage("--dim must be 2 or 3");
    if (o.method != "mba" && o.method != "rbf") usage("--method must be mba or rbf");
    if (o.k < 2 || o.n < 1 || o.eval < 0 || o.ranks < 1) usage("sizes must be positive (k >= 2)");
    return o;
}

/// Smooth field with a sharp Gaussian bump
template <int D> double field(const point<D>& x, double phase)
{
    double s = std::sin(2*M_PI*x[0] + phase)*std::cos(2*M_PI*x[1]);
    double r2 = (x[0] - 0.3)*(x[0] - 0.3) + (x[1] - 0.7)*(x[1] - 0.7);
    if (D == 3) { s *= std::cos(M_PI*x[D - 1]); r2 += (x[D - 1] - 0.5)*(x[D - 1] - 0.5); }
    return s + std::exp(-r2/0.002);
}

double seconds()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double peakMB()
{
    rusage u;
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss/1024.0;
}

template <int D> std::vector<point<D>> controlPoints(const options& o, std::mt19937_64& rng)
{
    std::vector<point<D>> p;
    std::uniform_real_distribution<double> U(0, 1);
    if (o.kase == "volume")
    {
        for (long i = 0; i < o.n; ++i) { point<D> x; for (auto& c : x) c = U(rng); p.push_back(x); }
        return p;
    }
    // k x k points on every face (D=3), k points on every edge (D=2)
    for (int d = 0; d < D; ++d)
        for (int side = 0; side < 2; ++side)
        {
            const long m = (D == 3) ? o.k*o.k : o.k;
            for (long i = 0; i < m; ++i)
            {
                point<D> x;
                long a = i % o.k, b = i / o.k;
                x[d] = side;
                x[(d + 1) % D] = double(a)/(o.k - 1);
                if (D == 3) x[(d + 2) % D] = double(b)/(o.k - 1);
                p.push_back(x);
            }
        }
    return p;
}

/// The benchmark problem: control points, random evaluation points (seeded),
/// and two sets of control values (a fit, then an apply with new values)
template <int D> struct problem
{
    std::vector<point<D>> ctrl, ev;
    std::vector<double> v1, v2;

    explicit problem(const options& o)
    {
        std::mt19937_64 rng(o.seed);
        ctrl = controlPoints<D>(o, rng);
        ev.resize(o.eval);
        std::uniform_real_distribution<double> U(0, 1);
        for (auto& x : ev) for (auto& c : x) c = U(rng);
        for (const auto& x : ctrl) { v1.push_back(field<D>(x, 0.0)); v2.push_back(field<D>(x, 0.7)); }
    }
};

struct result
{
    int levels = 0;
    double fit = 0, apply = 0, evalTime = 0, maxRes = 0, rmsRes = 0, applyDiff = 0;
    std::int64_t nodes = 0, bytes = 0, recvMax = 0, recvTotal = 0, gatherAll = 0, msgs = 0;
    std::vector<levelStats> stats;
    double peak = 0;
};

template <int D> int run(const options& o)
{
    const problem<D> pb(o);
    const std::vector<point<D>>& ctrl = pb.ctrl;
    const std::vector<point<D>>& ev = pb.ev;

    std::cout << "mbaBenchmark: case " << o.kase << ", dim " << D << ", control points " << ctrl.size()
              << ", evaluation points " << ev.size() << ", tolerance " << o.tolerance << " (relative)"
              << ", maxLevels " << o.maxLevels << ", initialGrid " << o.initialGrid
              << ", affine " << (o.affine ? "on" : "off") << ", ranks " << o.ranks
              << ", seed " << o.seed << std::endl;

    params prm;
    prm.tolerance = o.tolerance;
    prm.maxLevels = o.maxLevels;
    prm.initialGrid = o.initialGrid;
    prm.affine = o.affine;

    // Slabs along x for simulated ranks
    auto slab = [&](const point<D>& x) { return std::min(o.ranks - 1, int(x[0]*o.ranks)); };
    result res;
    std::mutex m;
    const double mem0 = peakMB();
    runSimulated(o.ranks, [&](const communicator& comm) {
        std::vector<point<D>> c, e;
        std::vector<double> v1, v2;
        for (std::size_t i = 0; i < ctrl.size(); ++i)
            if (slab(ctrl[i]) == comm.rank()) { c.push_back(ctrl[i]); v1.push_back(pb.v1[i]); v2.push_back(pb.v2[i]); }
        for (const auto& x : ev) if (slab(x) == comm.rank()) e.push_back(x);

        double t = seconds();
        std::unique_ptr<multilevel<D>> mba(new multilevel<D>(comm, prm, 1, c, {}, e));
        const fitReport& r1 = mba->fit(v1);
        const double tFit = comm.max(seconds() - t);
        const double maxRes = r1.maxResidual, rmsRes = r1.rmsResidual;
        const int levels = r1.levels;

        t = seconds();
        mba->fit(v2);
        const double tApply = comm.max(seconds() - t);

        t = seconds();
        std::vector<double> out, outFresh;
        mba->evaluate(out);
        const double tEval = comm.max(seconds() - t);

        std::int64_t recv = 0, msgs = 0, nodesLocal = 0;
        const std::vector<levelStats> st = mba->stats();
        for (const auto& s : st) { recv += s.bytesReceivedPerApply; msgs += s.messagesReceived; nodesLocal += s.nodes; }
        const double recvMax = comm.max(double(recv));
        const std::int64_t recvTotal = comm.sum(recv), msgsTotal = comm.sum(msgs);
        const std::int64_t nodes = comm.sum(nodesLocal);
        const std::int64_t bytes = comm.sum(mba->bytes());
        const double gatherAll = comm.max(double(mba->gatherAllBytes()));
        const double peak = peakMB();
        mba.reset();

        // apply through the plan equals a fresh fit with the same values
        multilevel<D> fresh(comm, prm, 1, c, {}, e);
        fresh.fit(v2);
        fresh.evaluate(outFresh);
        double diff = 0;
        for (std::size_t i = 0; i < out.size(); ++i) diff = std::max(diff, std::abs(out[i] - outFresh[i]));
        diff = comm.max(diff);
        if (comm.rank() == 0)
        {
            std::lock_guard<std::mutex> lock(m);
            res.levels = levels; res.fit = tFit; res.apply = tApply; res.evalTime = tEval;
            res.maxRes = maxRes; res.rmsRes = rmsRes; res.applyDiff = diff;
            res.nodes = nodes; res.bytes = bytes; res.recvMax = std::int64_t(recvMax);
            res.recvTotal = recvTotal; res.gatherAll = std::int64_t(gatherAll); res.msgs = msgsTotal;
            res.stats = st;
            res.peak = peak;
        }
    });

    std::printf("%5s %12s %8s %10s %6s %9s %8s %12s %12s %12s %9s %12s\n", "level", "h", "tiles", "nodes", "dense",
                "separated", "lone", "MB", "max res", "rms res", "time s", "recv/apply");
    for (const auto& s : res.stats)
        std::printf("%5d %12.4e %8lld %10lld %6s %9s %8lld %12.3f %12.3e %12.3e %9.4f %12lld\n", s.level, s.h,
                    static_cast<long long>(s.viewTiles), static_cast<long long>(s.nodes), s.dense ? "yes" : "no",
                    s.separated ? "yes" : "no", static_cast<long long>(s.lonePoints), s.bytes/1048576.0,
                    s.maxResidual, s.rmsResidual, s.seconds, static_cast<long long>(s.bytesReceivedPerApply));
    const double peak = res.peak;
    std::printf("fit %.4f s, apply %.4f s, evaluate %.4f s (%.2f M points/s), levels %d\n",
                res.fit, res.apply, res.evalTime, o.eval/std::max(res.evalTime, 1e-12)/1e6, res.levels);
    std::printf("max residual %.3e, rms residual %.3e (absolute; max |value| 1), apply vs fresh fit %.3e\n",
                res.maxRes, res.rmsRes, res.applyDiff);
    std::printf("nodes stored %lld, plan %.1f MB, peak memory %.1f MB after fit, apply and evaluation (%.1f MB before the plan)\n",
                static_cast<long long>(res.nodes), res.bytes/1048576.0, peak, mem0);
    if (o.ranks > 1)
        std::printf("exchange per apply: max %lld bytes received by one rank, %lld in total, %lld messages; "
                    "gather-all would need %lld bytes per rank\n",
                    static_cast<long long>(res.recvMax), static_cast<long long>(res.recvTotal), static_cast<long long>(res.msgs), static_cast<long long>(res.gatherAll));
    std::printf("RESULT case=%s dim=%d n_control=%zu n_eval=%ld ranks=%d levels=%d fit_s=%.6f apply_s=%.6f "
                "eval_s=%.6f eval_mpts_per_s=%.3f max_res=%.3e rms_res=%.3e apply_diff=%.3e nodes=%lld "
                "plan_mb=%.2f peak_mb=%.1f recv_bytes_max=%lld recv_bytes_total=%lld messages=%lld "
                "gather_all_bytes=%lld\n",
                o.kase.c_str(), D, ctrl.size(), o.eval, o.ranks, res.levels, res.fit, res.apply, res.evalTime,
                o.eval/std::max(res.evalTime, 1e-12)/1e6, res.maxRes, res.rmsRes, res.applyDiff,
                static_cast<long long>(res.nodes), res.bytes/1048576.0, peak, static_cast<long long>(res.recvMax),
                static_cast<long long>(res.recvTotal), static_cast<long long>(res.msgs), static_cast<long long>(res.gatherAll));
    return 0;
}

/// The RBF baseline (inverse multiquadric + linear polynomial, serial) on the
/// same points and values: setup (gather, assemble, factor), apply (solve for
/// new values), evaluation
template <int D> int runRbf(const options& o)
{
    const problem<D> pb(o);
    const std::vector<point<D>>& ctrl = pb.ctrl;
    const std::vector<point<D>>& ev = pb.ev;
    const std::vector<double>& v1 = pb.v1;
    const std::vector<double>& v2 = pb.v2;
    std::cout << "mbaBenchmark: RBF (inverse multiquadric, shapeParameter " << o.shape
              << ", linear polynomial), case " << o.kase << ", dim " << D << ", control points " << ctrl.size()
              << ", evaluation points " << ev.size() << ", seed " << o.seed << std::endl;
    rbf::params prm;
    prm.shapeParameter = o.shape;
    prm.maxPoints = 1000000;
    const serialCommunicator comm;
    const double mem0 = peakMB();
    double t = seconds();
    rbf::interpolant<D> s(comm, prm, 1, pointsView<D>(ctrl[0].data(), ctrl.size()));
    const double tSetup = seconds() - t;
    s.fit(v1);
    t = seconds();
    s.fit(v2);
    const double tApply = seconds() - t;
    std::vector<double> out, atCtrl;
    t = seconds();
    s.evaluate(pointsView<D>(ev[0].data(), ev.size()), out);
    const double tEval = seconds() - t;
    s.evaluate(pointsView<D>(ctrl[0].data(), ctrl.size()), atCtrl);
    double maxRes = 0;
    for (std::size_t i = 0; i < ctrl.size(); ++i) maxRes = std::max(maxRes, std::abs(atCtrl[i] - v2[i]));
    const rbf::systemStats& st = s.stats();
    std::printf("setup (gather, assemble, factor) %.4f s, apply %.4f s, evaluate %.4f s (%.2f M points/s)\n",
                tSetup, tApply, tEval, o.eval/std::max(tEval, 1e-12)/1e6);
    std::printf("system size %ld, reciprocal condition %.3e, max residual %.3e, factor %.1f MB, peak %.1f MB (%.1f before)\n",
                st.size, st.rcond, maxRes, st.bytes/1048576.0, peakMB(), mem0);
    std::printf("RESULT method=rbf case=%s dim=%d n_control=%zu n_eval=%ld setup_s=%.6f apply_s=%.6f eval_s=%.6f "
                "size=%ld rcond=%.3e max_res=%.3e factor_mb=%.2f peak_mb=%.1f\n",
                o.kase.c_str(), D, ctrl.size(), o.eval, tSetup, tApply, tEval, st.size, st.rcond, maxRes,
                st.bytes/1048576.0, peakMB());
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    const options o = parse(argc, argv);
    try
    {
        if (o.method == "rbf") return o.dim == 2 ? runRbf<2>(o) : runRbf<3>(o);
        return o.dim == 2 ? run<2>(o) : run<3>(o);
    }
    catch (const std::exception& e)
    {
        std::cerr << "mbaBenchmark: error: " << e.what() << std::endl;
        return 1;
    }
}
