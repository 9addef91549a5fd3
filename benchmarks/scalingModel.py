"""Strong-scaling model of the multilevel B-spline solve on the twisted cube.

    /usr/bin/python3 benchmarks/scalingModel.py RECORDS... [--real REAL] [--plot PNG] [--table]
    /usr/bin/python3 benchmarks/scalingModel.py --traffic RECORDS...
    /usr/bin/python3 benchmarks/scalingModel.py --exchanges RECORDS...

RECORDS are files with mbaScaling's RESULT lines (benchmarks/scaling writes
them): per rank count and decomposition, the busiest rank's work (thread CPU
time of its fit and evaluation, less the communicator's own time; with
mbaScaling --replay, as benchmarks/scaling runs it, each rank replayed alone
on a core, its communication answered as the simulated run answered it)
and what it receives per step (bytes, messages), the exchange rounds and
all-gathers of a step.

The model of one step on P ranks:

    T(P) = W(P) + R alpha + M o + B / beta + (G + S) ceil(log2 P) alpha

W: the busiest rank's work (fit and evaluation), measured alone (above); R: exchange rounds
(one a direct level, two a chunked one, 2 log2 P a tree one, two more where P
is not a power of two; each a latency alpha, its messages in flight
together); M, B: messages and bytes the busiest rank receives (o: the
receiver's overhead per message, beta: the bandwidth); G: the core's
all-gathers a step (the residual each level, the values' check and maximum,
the affine start's sums: all of one size on every rank, each ceil(log2 P)
rounds of the communicator's all-gather); S: the motion solver's own
reductions a step, through the same all-gather (SOLVER_REDUCTIONS, counted
in the code: whether any prescribed value is not finite, the control set's
counts, whether the control set changed, the fit's figures for the log
line, the inverted-cell check's counts: a 3D case without rigid layers,
which adds its own). Efficiency: T(1)/(P T(P)).
Networks (stated, not measured):

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

--plot PNG: the modelled speed-up and efficiency of the sizes from 8M cells
on, and a row of what the records measured: the messages and the bytes
(against the share, with the issue's 2x line) the busiest rank receives.
--real REAL: key=value lines of real runs (ranks=, solve_s=, fit_s=,
evaluation_s=: benchmarks/run's multilevelBSpline on the 1M mesh, medians) to
print beside the model of its smallest recorded size, slabs.
Prints a summary (efficiency and time per step per rank count); --table adds
a table of time per step, speed-up and efficiency per size, decomposition
and network.
--traffic: only a markdown table of the records themselves: per rank count
what the busiest rank receives (against its share of the boundary, 48 bytes
per control point, and against the least possible, mbaScaling --lower-bound),
its messages (also per neighbour and level), its work and the imbalance.
--exchanges: a markdown table of the same cases run with each of mbaScaling's
--exchange choices (benchmarks/scaling --exchanges writes them): per case and
choice the rounds, what the busiest rank receives, the model's cost of the
levels' exchange per step (R alpha + M o + B / beta) on both networks, and
beside it that of the step's all-gathers and reductions, which every choice
has; where the records hold mbaScaling --levels's lines, a second table sets
beside direct and automatic the cheapest choice per level on each network.
"""
import math
import sys
from collections import defaultdict

# the decompositions as the tables name them, in the order they list them
NAMES = {"simple": "slabs", "hierarchical": "boxes", "columns": "columns"}
ORDER = {"simple": 0, "hierarchical": 1, "columns": 2}
# mbaScaling's --exchange choices, in the order the tables list them
EXCHANGES = ["direct", "chunked", "tree", "automatic"]

# The motion solver's reductions a step outside the core (interpolatingMotionSolver
# with multilevelBSpline, a 3D case without rigid layers; see the header)
SOLVER_REDUCTIONS = 5

NETWORKS = {
    "infiniband": dict(alpha=2e-6, o=0.5e-6, beta=10e9),
    "ethernet25": dict(alpha=20e-6, o=2e-6, beta=3e9),
    "sharedMemory": dict(alpha=1e-6, o=0.3e-6, beta=5e9),
}


def result_lines(paths):
    """The RESULT lines of mbaScaling's output files, each as a dict (numbers
    as floats); with mbaScaling --levels, "level_lines" holds the per-level lines
    that follow it (the rank receiving most: level, its exchange, messages
    and bytes received; a separated level's exchange is a direct one)"""
    for path in paths:
        rec = None
        with open(path) as f:
            for line in f:
                w = line.split()
                if rec is not None and len(w) >= 6 and w[0].isdigit() and w[1] in ("direct", "chunked", "tree", "separate"):
                    rec["level_lines"].append((int(w[0]), "direct" if w[1] == "separate" else w[1], int(w[4]), int(w[5])))
                    continue
                if not line.startswith("RESULT "):
                    continue
                if rec is not None:
                    yield rec
                rec = {"level_lines": []}
                for kv in w[1:]:
                    k, v = kv.split("=", 1)
                    try:
                        rec[k] = float(v)
                    except ValueError:
                        rec[k] = v
        if rec is not None:
            yield rec


def read_records(paths):
    """{(n, decomposition): {ranks: record}} from mbaScaling RESULT lines; a
    rank count recorded more than once counts by its record of median work.
    Decompositions into the same parts are the same computation (one rank,
    1x1x1; two ranks, 2x1x1 for all three; 2x2x1 for boxes and columns on
    four): their runs at a size are pooled (benchmarks/scaling measures one
    rank three times per decomposition: every efficiency's baseline, the
    median of all one-rank runs of the size)"""
    runs = defaultdict(lambda: defaultdict(list))
    same = defaultdict(list)
    for rec in result_lines(paths):
        runs[(int(rec["n"]), rec["decomposition"])][int(rec["ranks"])].append(rec)
        same[(int(rec["n"]), rec["parts"])].append(rec)
    out = defaultdict(dict)
    for key, byRanks in runs.items():
        for P, recs in byRanks.items():
            recs = sorted(same[(key[0], recs[0]["parts"])], key=lambda r: r["work_max"])
            out[key][P] = dict(recs[(len(recs) - 1)//2], decomposition=key[1])
    return out


def exchange_time(rounds, messages, nbytes, net):
    """Modelled seconds of exchange rounds: R alpha + M o + B / beta"""
    return rounds*net["alpha"] + messages*net["o"] + nbytes/net["beta"]


def comm_times(rec, P, net):
    """Modelled seconds of the busiest rank's communication a step: the
    levels' exchange (R alpha + M o + B / beta) and the all-gathers and
    reductions ((G + S) ceil(log2 P) alpha)"""
    if P == 1:
        return 0.0, 0.0
    return (exchange_time(rec["exchanges"], rec["messages_max"], rec["recv_bytes_max"], net),
            (rec["all_gathers"] + SOLVER_REDUCTIONS)*math.ceil(math.log2(P))*net["alpha"])


def step_time(rec, P, net):
    """Modelled seconds of one step of the busiest rank"""
    return rec["work_max"] + sum(comm_times(rec, P, net))


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
                r["work_max"] = r["fit_cpu_max"]/f**2 + r["eval_cpu_max"]/f**3
                out[P] = r
            continue
        q = int(round(q))
        if q not in base:
            continue
        r = dict(base[q])
        # the busiest rank's work with its fit part scaled (the ratio of its
        # parts taken from the busiest fit and evaluation)
        fit, ev = r["fit_cpu_max"], r["eval_cpu_max"]
        r["work_max"] *= (f*fit + ev)/(fit + ev)
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


def traffic_table(records):
    """Markdown: per size, decomposition and rank count, what the busiest rank receives and works"""
    print("| cells | decomposition | ranks | parts | max control points of a rank | max neighbours "
          "| max bytes received per step | / share | least possible / share | max messages received "
          "| / (neighbours x levels) | fit s (max, mean) | evaluation s (max, mean) | imbalance |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (n, d) in sorted(records, key=lambda k: (k[0], ORDER.get(k[1], 3), k[1])):
        for P in sorted(records[(n, d)]):
            r = records[(n, d)][P]
            share = r["share_bytes"]
            bound = r.get("lower_bound_max", 0)
            print("| %.3gM | %s | %d | %s | %d | %d | %d | %s | %s | %d | %s | %.4f, %.4f | %.4f, %.4f | %.2f |" % (
                n**3/1e6, NAMES.get(d, d), P, r["parts"], r["ctrl_max"], r["neighbours_max"], r["recv_bytes_max"],
                "%.2f" % (r["recv_bytes_max"]/share) if P > 1 else "-",
                "%.2f" % (bound/share) if P > 1 and bound else "-", r["messages_max"],
                "%.1f" % r["messages_per_neighbour_level_max"] if P > 1 else "-",
                r["fit_cpu_max"], r["fit_cpu_mean"], r["eval_cpu_max"], r["eval_cpu_mean"],
                r["work_max"]/r["work_mean"]))


def exchanges_table(paths):
    """Markdown: per size, decomposition and rank count, each --exchange choice's traffic and modelled cost"""
    rows = {}
    for rec in result_lines(paths):
        rows[(int(rec["n"]), ORDER.get(rec["decomposition"], 3), int(rec["ranks"]),
              EXCHANGES.index(rec["exchange"]))] = rec
    print("| cells | decomposition | ranks | exchange | rounds | max messages | max bytes received | / share "
          "| exchange s, infiniband | exchange s, ethernet25 | all-gathers and reductions s, infiniband |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for key in sorted(rows):
        r = rows[key]
        P = key[2]
        # T(P)'s terms: the levels' exchange, and the collectives that every choice has
        exch = lambda net: comm_times(r, P, NETWORKS[net])[0]
        coll = lambda net: comm_times(r, P, NETWORKS[net])[1]
        print("| %.3gM | %s | %d | %s | %d | %d | %d | %.2f | %.5f | %.5f | %.5f |" % (
            key[0]**3/1e6, NAMES.get(r["decomposition"], r["decomposition"]), P, r["exchange"], r["exchanges"],
            r["messages_max"], r["recv_bytes_max"], r["recv_bytes_max"]/r["share_bytes"],
            exch("infiniband"), exch("ethernet25"), coll("infiniband")))
    cheapest_per_level(rows)


def level_cost(exchange, P, messages, nbytes, net):
    """Modelled seconds of one level's exchange: its rounds (one direct, two
    chunked, the tree's 2 ceil(log2 P), two more where P is not a power of
    two; none where nothing is received), messages and bytes"""
    if messages == 0:
        return 0.0
    rounds = {"direct": 1, "chunked": 2,
              "tree": 2*math.ceil(math.log2(P)) + (2 if P & (P - 1) else 0)}[exchange]
    return exchange_time(rounds, messages, nbytes, net)


def cheapest_per_level(rows):
    """Markdown, from mbaScaling --levels's lines (the rank receiving most
    in each choice's run): per case and network, the cost of the levels'
    exchange with direct and with automatic, and with the cheapest of direct,
    chunked and tree taken per level, and that mix (d, c, t a level; - where
    the rank receives nothing)"""
    cases = defaultdict(dict)
    for (n, o, P, x), r in rows.items():
        cases[(n, o, P)][EXCHANGES[x]] = r
    usable = {k: v for k, v in cases.items()
              if all(x in v and v[x]["level_lines"] for x in EXCHANGES)}
    if not usable:
        return
    print("\nThe cheapest choice per level (each choice's run's rank receiving most, per level its messages and bytes; "
          "mbaScaling --levels):\n")
    print("| cells | decomposition | ranks | network | direct s | automatic s | cheapest per level s | its choices |")
    print("|---|---|---|---|---|---|---|---|")
    for key in sorted(usable):
        v = usable[key]
        n, P = key[0], key[2]
        d = v["direct"]["decomposition"]
        for name in ("infiniband", "ethernet25"):
            net = NETWORKS[name]
            total = lambda x: sum(level_cost(e, P, m, b, net) for _, e, m, b in v[x]["level_lines"])
            byLevel = defaultdict(dict)
            for x in ("direct", "chunked", "tree"):
                for k, e, m, b in v[x]["level_lines"]:
                    byLevel[k][e] = level_cost(e, P, m, b, net)
            best = [min(byLevel[k].items(), key=lambda kv: kv[1]) for k in sorted(byLevel)]
            print("| %.3gM | %s | %d | %s | %.5f | %.5f | %.5f | %s |" % (
                n**3/1e6, NAMES.get(d, d), P, name, total("direct"), total("automatic"),
                sum(c for _, c in best), "".join(e[0] if c > 0 else "-" for e, c in best)))


def main(argv):
    paths, real, plot, table = [], None, None, False
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("-h", "--help", "-help"):
            print(__doc__)
            return
        if a in ("--real", "--plot") and i + 1 == len(argv):
            sys.exit("scalingModel.py: option %s needs a value (--help)" % a)
        if a == "--real":
            real = argv[i + 1]; i += 2; continue
        if a == "--plot":
            plot = argv[i + 1]; i += 2; continue
        if a == "--table":
            table = True; i += 1; continue
        if a == "--traffic":
            traffic_table(read_records(argv[i + 1:]))
            return
        if a == "--exchanges":
            exchanges_table(argv[i + 1:])
            return
        if a.startswith("-"):
            sys.exit("scalingModel.py: unknown option %s (--help: the options)" % a)
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
    # the summary: efficiency per rank count, per size, decomposition and network
    shown = [2, 8, 16, 32, 64, 128, 256]
    print("| cells | decomposition | network | s per step on 1 rank | " +
          " | ".join("%d ranks" % P for P in shown) + " |")
    print("|---|---|---|---|" + "---|"*len(shown))
    for n, decomposition, name, rows in sorted(cases, key=lambda c: (c[0], ORDER.get(c[1], 3), c[2])):
        by = {P: (t, e) for P, t, _, e in rows}
        cell = lambda P: "%.0f%% (%.4f s)" % (100*by[P][1], by[P][0]) if P in by else "-"
        print("| %.3gM%s | %s | %s | %.3f | %s |" % (n**3/1e6, "" if (n, decomposition) in records else " (scaled)",
                                                  NAMES.get(decomposition, decomposition), name, by[1][0],
                                                  " | ".join(cell(P) for P in shown)))
    print()
    for n, decomposition, name, rows in (cases if table else []):
        print("%d^3 = %.3gM cells, %s, %s%s:" % (n, n**3/1e6, decomposition, name,
                                                 "" if (n, decomposition) in records else " (scaled)"))
        print("\n| ranks | s per step | speed-up | efficiency |\n|---|---|---|---|")
        for P, t, s, e in rows:
            print("| %d | %.4f | %.1f | %.0f%% |" % (P, t, s, 100*e))
        print()
    if real:
        # the model's core (fit, evaluation, exchange) against the real runs'
        # fit and evaluation (the solver's table: rank 0's, medians of the later steps)
        measured = {}
        with open(real) as f:
            for line in f:
                kv = dict(x.split("=", 1) for x in line.split() if "=" in x)
                if "ranks" in kv and "fit_s" in kv:
                    measured[int(kv["ranks"])] = kv
        n = min(sizes)
        recs = records.get((n, "simple"), {})
        print("\nagainst real mpirun runs (%d^3 cells, slabs; sharedMemory network):\n" % n)
        print("| ranks | model: fit + evaluation + exchange s | real: fit + evaluation s | real solve s |")
        print("|---|---|---|---|")
        for P in sorted(measured):
            if P in recs:
                kv = measured[P]
                t = step_time(recs[P], P, NETWORKS["sharedMemory"])
                print("| %d | %.4f | %.4f | %.4f |" % (P, t, float(kv["fit_s"]) + float(kv["evaluation_s"]),
                                                   float(kv["solve_s"])))
        if 1 in measured and 2 in measured and 1 in recs and 2 in recs:
            em = step_time(recs[1], 1, NETWORKS["sharedMemory"])/(2*step_time(recs[2], 2, NETWORKS["sharedMemory"]))
            core = lambda kv: float(kv["fit_s"]) + float(kv["evaluation_s"])
            print("\n2-rank efficiency: model %.0f%%, real fit + evaluation %.0f%%, real solve %.0f%%" %
                  (100*em, 100*core(measured[1])/(2*core(measured[2])),
                   100*float(measured[1]["solve_s"])/(2*float(measured[2]["solve_s"]))))
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        big = sorted({n for n, _, _, _ in cases if n >= 200})
        fig, axes = plt.subplots(len(big) + 1, 2, figsize=(11, 4*(len(big) + 1)), squeeze=False)
        colours = {"simple": "tab:red", "hierarchical": "tab:blue", "columns": "tab:green"}
        # what the busiest rank receives per step, as measured (the records)
        m1, m2 = axes[-1]
        for (n, decomposition), byRanks in sorted(records.items()):
            P = sorted(p for p in byRanks if p > 1)
            style = "-" if n == max(sizes) else "--"
            label = "%s, %.3gM cells" % (NAMES.get(decomposition, decomposition), n**3/1e6)
            m1.semilogx(P, [byRanks[p]["messages_max"] for p in P], style, color=colours.get(decomposition),
                      marker="o", ms=3, label=label)
            m2.loglog(P, [byRanks[p]["recv_bytes_max"]/byRanks[p]["share_bytes"] for p in P], style,
                      color=colours.get(decomposition), marker="o", ms=3, label=label)
        m1.set_title("measured: the busiest rank's messages per step")
        m2.set_title("measured: the busiest rank's bytes / its boundary share")
        m1.set_ylabel("messages")
        m2.set_ylabel("bytes / share")
        m2.axhline(2, color="k", lw=0.6, ls=":")
        for a in (m1, m2):
            a.set_xlabel("ranks")
            a.set_xticks(ranks[1:])
            a.set_xticklabels([str(r) for r in ranks[1:]])
            a.minorticks_off()
            a.grid(alpha=0.3)
        m1.legend(fontsize=7, loc="upper left")
        for row, n in zip(axes, big):
            a1, a2 = row
            for m, decomposition, name, rows in cases:
                if m != n:
                    continue
                P = [r[0] for r in rows]
                style = "-" if name == "infiniband" else "--"
                # a decomposition without records of this size is scaled from another size's
                label = "%s, %s%s" % (NAMES.get(decomposition, decomposition), name,
                                      "" if (n, decomposition) in records else " (scaled)")
                a1.loglog(P, [r[2] for r in rows], style, color=colours.get(decomposition), marker="o", ms=3, label=label)
                a2.semilogx(P, [100*r[3] for r in rows], style, color=colours.get(decomposition), marker="o", ms=3,
                            label=label)
            scaledNote = "" if any((n, d) in records for d in NAMES) else " (scaled from %d^3)" % max(sizes)
            a1.loglog([1, 256], [1, 256], "k:", lw=0.8, label="ideal")
            a1.set_title("%.3gM cells%s: modelled speed-up" % (n**3/1e6, scaledNote))
            a2.set_title("%.3gM cells: modelled efficiency" % (n**3/1e6))
            a1.set_ylabel("speed-up")
            a2.set_ylabel("efficiency %")
            top = max([100*r[3] for m, d, nm, rows in cases if m == n for r in rows] + [100])
            a2.set_ylim(0, 10*math.ceil(top/10 + 0.5))
            a2.axhline(80, color="k", lw=0.6, ls=":")
            for a in (a1, a2):
                a.set_xlabel("ranks")
                a.set_xticks(ranks)
                a.set_xticklabels([str(r) for r in ranks])
                a.minorticks_off()
                a.grid(alpha=0.3)
            a2.legend(fontsize=7, loc="lower left")
        fig.suptitle("Twisted cube, multilevelBSpline's fit, evaluation, exchange and reductions per step (benchmarks/scaling);"
                     " bottom: the measured exchange (mbaScaling)",
                     fontsize=10)
        fig.tight_layout()
        fig.savefig(plot, dpi=100)
        print("wrote", plot)


if __name__ == "__main__":
    main(sys.argv[1:])
