"""Strong-scaling model of the multilevel B-spline solve on the twisted cube.

    /usr/bin/python3 benchmarks/scalingModel.py RECORDS... [--real REAL] [--plot PNG] [--table]

RECORDS are files with mbaScaling's RESULT lines (benchmarks/scaling writes
them): per rank count and decomposition, the busiest rank's work (thread CPU
time of its fit and evaluation, less the simulated communicator's own time)
and what it receives per step (bytes, messages), the exchange rounds and
all-gathers of a step.

The model of one step on P ranks:

    T(P) = W(P) + R alpha + M o + B / beta + G 2 ceil(log2 P) alpha

W: the busiest rank's work, measured on simulated ranks; R: exchange rounds
(one a direct level, two a chunked one; each a latency alpha, its messages in
flight together); M, B: messages and bytes the busiest rank receives (o: the
receiver's overhead per message, beta: the bandwidth); G: all-gathers (the
residual each level; gatherList and scatterList: two trees of log2 P
latencies). Efficiency: T(1)/(P T(P)). Networks (stated, not measured):

    infiniband  alpha 2 us,  o 0.5 us, beta 10 GB/s  (HDR/EDR-class)
    ethernet25  alpha 20 us, o 2 us,   beta 3 GB/s   (25 GbE, TCP)
    sharedMemory alpha 1 us, o 0.3 us, beta 5 GB/s   (ranks of one machine: for
                 checking the model against real mpirun runs on this machine)

Sizes without records of their own (64M cells: its simulation does not fit in
memory here) are scaled from the largest recorded size m^3 to n^3 (cube of
the cells per edge) at the same cells per rank: P ranks at n^3 are P (m/n)^3
ranks at m^3; the evaluation work is the same per rank, the fit work and the
bytes scale with the boundary per rank, (m/n) times as much, the messages and
rounds stay. Rank counts below the recorded ones take the serial work times
(n/m)^3 (evaluation) and (n/m)^2 (fit).

--real REAL: key=value lines of real runs (ranks=, solve_s=: benchmarks/run's
multilevelBSpline solve on the same mesh) to print beside the model.
--table: a markdown table of time per step, speed-up and efficiency.
"""
import math
import sys
from collections import defaultdict

NETWORKS = {
    "infiniband": dict(alpha=2e-6, o=0.5e-6, beta=10e9),
    "ethernet25": dict(alpha=20e-6, o=2e-6, beta=3e9),
    "sharedMemory": dict(alpha=1e-6, o=0.3e-6, beta=5e9),
}


def read_records(paths):
    """{(n, decomposition): {ranks: record}} from mbaScaling RESULT lines"""
    out = defaultdict(dict)
    for path in paths:
        with open(path) as f:
            for line in f:
                if not line.startswith("RESULT "):
                    continue
                rec = {}
                for kv in line.split()[1:]:
                    k, v = kv.split("=", 1)
                    try:
                        rec[k] = float(v)
                    except ValueError:
                        rec[k] = v
                out[(int(rec["n"]), rec["decomposition"])][int(rec["ranks"])] = rec
    return out


def step_time(rec, P, net):
    """Modelled seconds of one step of the busiest rank"""
    work = rec["fit_cpu_max"] + rec["eval_cpu_max"]
    if P == 1:
        return work
    comm = (rec["exchanges"]*net["alpha"] + rec["messages_max"]*net["o"] + rec["recv_bytes_max"]/net["beta"]
            + rec["all_gathers"]*2*math.ceil(math.log2(P))*net["alpha"])
    return work + comm


def scaled(records, n, ranks):
    """Records for n^3 cells scaled from the largest recorded size of the same decomposition"""
    m = max(records)
    base = records[m]
    f = m/n
    out = {}
    for P in ranks:
        q = P*f**3
        if q < 1:
            if P == 1 and 1 in base:
                r = dict(base[1])
                r["fit_cpu_max"] *= 1/f**2
                r["eval_cpu_max"] *= 1/f**3
                out[P] = r
            continue
        q = int(round(q))
        if q not in base:
            continue
        r = dict(base[q])
        r["fit_cpu_max"] *= f
        r["recv_bytes_max"] *= f
        out[P] = r
    return out


def model(records, n, decomposition, net, ranks):
    recs = records.get((n, decomposition))
    if recs is None:
        recs = scaled({k[0]: v for k, v in records.items() if k[1] == decomposition}, n, ranks)
    rows = []
    if 1 not in recs:
        return rows
    t1 = step_time(recs[1], 1, net)
    for P in sorted(recs):
        if P not in ranks:
            continue
        t = step_time(recs[P], P, net)
        rows.append((P, t, t1/t, t1/(P*t)))
    return rows


def main(argv):
    paths, real, plot, table = [], None, None, False
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--real":
            real = argv[i + 1]; i += 2; continue
        if a == "--plot":
            plot = argv[i + 1]; i += 2; continue
        if a == "--table":
            table = True; i += 1; continue
        paths.append(a); i += 1
    if not paths:
        sys.exit(__doc__)
    records = read_records(paths)
    ranks = [1, 2, 4, 8, 16, 32, 64, 128, 256]
    sizes = sorted({n for n, _ in records})
    cases = []
    for decomposition in sorted({d for _, d in records}):
        for n in sorted(set(sizes) | {400}):
            for name in ("infiniband", "ethernet25"):
                rows = model(records, n, decomposition, NETWORKS[name], ranks)
                if rows:
                    cases.append((n, decomposition, name, rows))
    for n, decomposition, name, rows in cases:
        print("%d^3 cells (%.0fM), %s, %s:" % (n, decomposition and n**3/1e6, decomposition, name) if False else
              "%d^3 = %.3gM cells, %s, %s%s:" % (n, n**3/1e6, decomposition, name,
                                                   "" if (n, decomposition) in records else " (scaled)"))
        if table:
            print("\n| ranks | s per step | speed-up | efficiency |\n|---|---|---|---|")
            for P, t, s, e in rows:
                print("| %d | %.4f | %.1f | %.0f%% |" % (P, t, s, 100*e))
            print()
        else:
            for P, t, s, e in rows:
                print("  %4d ranks: %.5f s per step, speed-up %6.1f, efficiency %5.1f%%" % (P, t, s, 100*e))
    if real:
        measured = {}
        with open(real) as f:
            for line in f:
                kv = dict(x.split("=", 1) for x in line.split() if "=" in x)
                if "ranks" in kv and "solve_s" in kv:
                    measured[int(kv["ranks"])] = float(kv["solve_s"])
        n = min(sizes)
        recs = records[(n, "simple")]
        print("against real mpirun runs (%d^3 cells, slabs, sharedMemory network):" % n)
        for P in sorted(measured):
            if P in recs:
                t = step_time(recs[P], P, NETWORKS["sharedMemory"])
                print("  %d ranks: model %.4f s (work %.4f), real solve %.4f s" %
                      (P, t, recs[P]["fit_cpu_max"] + recs[P]["eval_cpu_max"], measured[P]))
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
        for n, decomposition, name, rows in cases:
            P = [r[0] for r in rows]
            style = "-" if name == "infiniband" else "--"
            label = "%.3gM cells, %s, %s" % (n**3/1e6, "slabs" if decomposition == "simple" else "boxes", name)
            a1.loglog(P, [r[2] for r in rows], style, marker="o", ms=3, label=label)
            a2.semilogx(P, [100*r[3] for r in rows], style, marker="o", ms=3, label=label)
        a1.loglog([1, 256], [1, 256], "k:", lw=0.8, label="ideal")
        a1.set_xlabel("ranks"); a1.set_ylabel("speed-up"); a1.set_title("Modelled strong scaling (twisted cube)")
        a2.set_xlabel("ranks"); a2.set_ylabel("efficiency %"); a2.set_ylim(0, 105)
        a2.axhline(80, color="k", lw=0.6, ls=":")
        for a in (a1, a2):
            a.set_xticks(ranks); a.set_xticklabels([str(r) for r in ranks]); a.grid(alpha=0.3)
        a2.legend(fontsize=6.5, loc="lower left")
        fig.tight_layout()
        fig.savefig(plot, dpi=110)
        print("wrote", plot)


if __name__ == "__main__":
    main(sys.argv[1:])
