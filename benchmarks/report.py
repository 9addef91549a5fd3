#!/usr/bin/env python3
"""benchmarks/run's records and tables (the twisted cube's performance and
scaling runs; see benchmarks/run and BENCHMARKS.md).

    report.py record N METHOD RANKS CASE
        one run's record, a line of log/bench/runs.txt, on stdout, from its
        case folder: CASE/peakKB (GNU time's peak memory), the solver's own
        table postProcessing/<solver>/<startTime>/<solver>.dat (plan MB,
        bytes and messages of the last step, fit, evaluation and
        inverted-cell check times of every step), postProcessing/morphQuality.dat
        (its last row) and log.motionSolverTimes (each step's solve and mesh
        update, the control points, the rigid zone, the steps with inverted
        cells)
    report.py tables RUNS MD IMAGES SCALEN PLOTS
        the markdown tables of the records in RUNS (printed and written to MD)
        and, with PLOTS 1, IMAGES/bench-growth.png and bench-scaling.png
        (matplotlib); SCALEN: the size of the strong-scaling runs

A record (one line, words separated by spaces; "-" for a figure the run has
not):

    n method ranks peakKB planMB bytes bytesOneRank messages messagesOneRank
    maxNonOrth maxSkewness nInvalid SOLVE s1 ... UPDATE u1 ... FIT f1 ...
    EVAL e1 ... CHECK c1 ... CONTROLS c ZONE z i o INVERTED k m

(RECORD below names the leading fields; each section runs up to the next
keyword; records written before the solvers' tables existed, from their log
lines, read the same; older ones may lack CHECK, CONTROLS, ZONE, INVERTED.)
A run that failed is "n method ranks failed".
"""
import math, os, re, sys
sys.dont_write_bytecode = True     # (no __pycache__ in the source tree)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bin"))
import bsmdata

# the leading fields of a record, in order; then the keyword sections
RECORD = ("n", "method", "ranks", "peakKB", "planMB", "bytes", "bytesOneRank", "messages", "messagesOneRank",
          "maxNonOrth", "maxSkewness", "nInvalid")
SECTIONS = ("SOLVE", "UPDATE", "FIT", "EVAL", "CHECK", "CONTROLS", "ZONE", "INVERTED")

def readRecord(line):
    """(fields: {RECORD name: text}, sections: {keyword: [text, ...]}); None for a failed run"""
    v = line.split()
    if len(v) < len(RECORD) or v[3] == "failed":
        return None
    keys = [i for i, x in enumerate(v) if x in SECTIONS] + [len(v)]
    return dict(zip(RECORD, v)), {v[i]: v[i + 1:j] for i, j in zip(keys[:-1], keys[1:])}

def record(n, method, ranks, case):
    """The record of the run in case (benchmarks/run's case folder) as a line"""
    peak = open(os.path.join(case, "peakKB")).read().split("\n")
    peak = [x for x in peak if x.strip()][-1].strip()
    # the solver's table (multilevelBSpline+rigidLayers: multilevelBSpline's;
    # rigid and displacementLaplacian have none). Bytes, messages and the plan
    # are the last step's; a re-fit's own figures (refit_...) are left out:
    # the twisted cube has none
    table = bsmdata.solverTable(case, method.split("+")[0])
    last = table[-1] if table else {}
    text = lambda c: last.text[c] if c in last else "-"
    count = lambda c: "%d" % last[c] if c in last else "-"
    steps = lambda c: [r.text[c] for r in table if c in r]
    q = bsmdata.lastRow(os.path.join(case, "postProcessing", "morphQuality.dat"))
    quality = [q.text[c] for c in ("maxNonOrth", "maxSkewness", "nInvalid")] if q else ["-"] * 3
    # the log: motionSolverTimes' step lines, the plan's control points (the
    # first plan), rigidLayers' zone (its last plan), the inverted-cell warnings
    solve, update = [], []
    controls, zone, nInverted, mostInverted = "-", ["-", "-", "-"], 0, 0
    for line in open(os.path.join(case, "log.motionSolverTimes")):
        m = re.match(r"motionSolverTimes: step \S+ (\S+) s, mesh update (\S+) s", line)
        if m:
            solve.append(m.group(1)); update.append(m.group(2))
        m = re.match(r"multilevelBSpline: plan for (\S+)", line)
        if m and controls == "-":
            controls = m.group(1)
        if line.startswith("rigidLayers: "):
            w = line.split()
            zone = [w[1], "-", "-"]
            for i in range(len(w) - 2):
                if w[i + 1] == "within" and w[i + 2] == "innerDistance":
                    zone[1] = w[i].replace("(", "")
                if w[i + 1] == "of" and w[i + 2] == "them":
                    zone[2] = w[i]
        m = re.search(r"The morphed mesh has (\d+) inverted cells", line)
        if m:
            nInverted += 1
            mostInverted = max(mostInverted, int(m.group(1)))
    words = [n, method, ranks, peak, text("planMB"), count("bytes"), count("bytesOneRank"),
             count("messages"), count("messagesOneRank")] + quality
    words += ["SOLVE"] + solve + ["UPDATE"] + update
    words += ["FIT"] + steps("fit_s") + ["EVAL"] + steps("evaluation_s") + ["CHECK"] + steps("check_s")
    words += ["CONTROLS", controls, "ZONE"] + zone + ["INVERTED", str(nInverted), str(mostInverted)]
    return " ".join(words)

def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt

rigidLayers = "multilevelBSpline+rigidLayers"
overSpline = rigidLayers + "+thinPlateSpline"
def median(v):
    v = sorted(v)
    return 0.5 * (v[(len(v) - 1) // 2] + v[len(v) // 2])

def tables(resultsPath, mdPath, imgDir, scaleN, plots):
    written = []   # the plots saved
    # every trial of a case: its first step, and its later steps pooled
    runs = {}
    for line in open(resultsPath):
        rec = readRecord(line)
        if rec is None:
            print("failed run:", line.strip()); continue
        f, sec = rec
        n, s, np_ = int(f["n"]), f["method"], int(f["ranks"])
        numbers = lambda k: [float(x) for x in sec.get(k, [])]
        solve, update, fit, ev, check = numbers("SOLVE"), numbers("UPDATE"), numbers("FIT"), numbers("EVAL"), numbers("CHECK")
        r = runs.setdefault((n, s, np_), dict(peakMB=0, plan=f["planMB"], bytes=f["bytes"], bytesMax=f["bytesOneRank"],
                                              messages=f["messages"], messagesMax=f["messagesOneRank"],
                                              nonOrth=f["maxNonOrth"], skew=f["maxSkewness"], invalid=f["nInvalid"],
                                              first=[], solve=[], update=[], trials=[],
                                              fit=[], eval=[], check=[], rest=[],
                                              controls=(sec.get("CONTROLS") or ["-"])[0], zone=sec.get("ZONE") or ["-", "-", "-"],
                                              inverted=[]))
        if "INVERTED" in sec:
            r["inverted"].append(sec["INVERTED"])
        if len(fit) == len(solve) == len(ev):
            if len(check) != len(solve):
                check = [0.0] * len(solve)
            else:
                r["check"] += check[1:]
            r["fit"] += fit[1:]
            r["eval"] += ev[1:]
            r["rest"] += [a - b - c - d for a, b, c, d in zip(solve[1:], fit[1:], ev[1:], check[1:])]
        r["peakMB"] = max(r["peakMB"], float(f["peakKB"]) / 1024)
        r["first"].append(solve[0])
        r["solve"] += solve[1:]
        r["update"] += update[1:]
        r["trials"].append(median(solve[1:]))
    def first(n, s, np_):
        return median(runs[(n, s, np_)]["first"])
    def solve(n, s, np_):
        return median(runs[(n, s, np_)]["solve"])
    def best(n, s, np_):
        return min(runs[(n, s, np_)]["solve"])
    def update(n, s, np_):
        return median(runs[(n, s, np_)]["update"])
    def overRigid(n, s, np_):
        # None without the rigid run (--methods without rigid)
        r, rigid = runs[(n, s, np_)], runs.get((n, "rigid", np_))
        total = median([a + b for a, b in zip(r["solve"], r["update"])])
        return total - update(n, "rigid", np_) if rigid else None
    f3 = lambda x: "%.3f" % x if x is not None else "-"
    fmt = lambda v, f: f % float(v) if v not in ("-", "") else "-"
    out = ["## Time per step, set-up and memory (single core)", "",
           "| cells | method | first step s (set-up + morph) | solve s | mesh update s | step over rigid s | peak memory MB | morpher plan MB | max non-orth | max skewness | invalid cells | solve / multilevelBSpline's | step over rigid / multilevelBSpline's |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    sizes = sorted({k[0] for k in runs})
    for n in sizes:
        b = (n, "multilevelBSpline", 1)
        for s in ("multilevelBSpline", rigidLayers, overSpline, "displacementLaplacian", "RBF"):
            if (n, s, 1) not in runs: continue
            r = runs[(n, s, 1)]
            out.append("| %d | %s | %.3f | %.3f | %.3f | %s | %.0f | %s | %s | %s | %s | %s | %s |" % (
                n**3, s, first(n, s, 1), solve(n, s, 1), update(n, s, 1), f3(overRigid(n, s, 1)), r["peakMB"],
                fmt(r["plan"], "%.0f"), fmt(r["nonOrth"], "%.1f"), fmt(r["skew"], "%.2f"), r["invalid"],
                "%.1f" % (solve(n, s, 1) / solve(*b)) if b in runs else "-",
                "%.1f" % (overRigid(n, s, 1) / overRigid(*b)) if b in runs and overRigid(*b) else "-"))
        if (n, "rigid", 1) in runs:
            out.append("| %d | (rigid motion: the bare mesh update) | - | %.3f | %.3f | - | %.0f | - | - | - | - | - | - |" % (
                n**3, solve(n, "rigid", 1), update(n, "rigid", 1), runs[(n, "rigid", 1)]["peakMB"]))
    # where multilevelBSpline's solve goes: its own fit, evaluation and
    # inverted-cell check times (rank 0's in parallel, where the solve is the
    # slowest rank's) and the rest
    parts = sorted(k for k in runs if k[1] == "multilevelBSpline" and runs[k]["fit"])
    if parts:
        out += ["", "## Where the solve of multilevelBSpline goes (medians of the later steps)", "",
                "| cells | ranks | solve s | fit s | evaluation s | inverted-cell check s | the rest s (conditions, control set, new points) |",
                "|---|---|---|---|---|---|---|"]
        for k in parts:
            r = runs[k]
            out.append("| %d | %d | %.3f | %.3f | %.3f | %s | %.3f |" % (
                k[0]**3, k[2], solve(*k), median(r["fit"]), median(r["eval"]),
                "%.3f" % median(r["check"]) if r["check"] else "-", median(r["rest"])))
    # multilevelBSpline with rigidLayers against without, serial: the solve
    # medians pooled over the same trials, each trial's ratio (the trials in the
    # order run), the first step, and where the solve goes
    layered = [n for n in sizes if (n, rigidLayers, 1) in runs or (n, overSpline, 1) in runs]
    if layered:
        out += ["", "## multilevelBSpline with rigidLayers against without (single core; rigidLayers on top: innerDistance 0.06, outerDistance 0.08)", "",
                "| cells | method | control points | rigid zone: points within outerDistance / innerDistance / outermost | first step s | solve s (median) | median of each trial | fit s | evaluation s | inverted-cell check s | the rest s | solve / multilevelBSpline's | each trial's | first step / multilevelBSpline's | steps with inverted cells (most in a step), each trial | invalid cells at the end |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for n in layered:
            b = (n, "multilevelBSpline", 1)
            for s in ("multilevelBSpline", rigidLayers, overSpline):
                k = (n, s, 1)
                if k not in runs: continue
                r = runs[k]
                part = lambda x: "%.3f" % median(r[x]) if r[x] else "-"
                out.append("| %d | %s | %s | %s | %.3f | %.3f | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                    n**3, s, r["controls"], " / ".join(r["zone"]) if s != "multilevelBSpline" else "-", first(*k), solve(*k),
                    ", ".join("%.3f" % x for x in r["trials"]), part("fit"), part("eval"), part("check"), part("rest"),
                    "%.2f" % (solve(*k) / solve(*b)) if b in runs else "-",
                    ", ".join("%.2f" % (x / y) for x, y in zip(r["trials"], runs[b]["trials"])) if b in runs else "-",
                    "%.2f" % (first(*k) / first(*b)) if b in runs else "-",
                    ", ".join("%s (%s)" % tuple(x) for x in r["inverted"]) or "-", r["invalid"]))
    # a rank's share of the boundary: its control points' coordinates and values
    # (48 bytes each; the slabs split the top and bottom faces, 2 (n+1)^2 points, evenly)
    share = lambda n, np_: 2 * (n + 1)**2 * 48 / np_
    scalRanks = sorted({k[2] for k in runs if k[0] == scaleN and k[1] == "multilevelBSpline"})
    if scalRanks: out += ["", "## Strong scaling of multilevelBSpline, %d cells" % scaleN**3, "",
            "| ranks | first step s | solve s (median) | median of each trial | speed-up | efficiency | efficiency of each trial (against its one-rank run) | median of those | fastest step s | its speed-up | its efficiency | bytes exchanged per step (all ranks) | max by one rank | gather-all bytes per rank | a rank's share of the boundary, bytes | max by one rank / share | messages per step (all ranks) | max by one rank | gather-all messages per rank |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    one = (scaleN, "multilevelBSpline", 1)
    t1, b1 = (solve(*one), best(*one)) if one in runs else (None, None)
    scal = []
    for np_ in scalRanks:
        r = runs[(scaleN, "multilevelBSpline", np_)]
        t, b = solve(scaleN, "multilevelBSpline", np_), best(scaleN, "multilevelBSpline", np_)
        sp = t1 / t if t1 else float("nan")
        spb = b1 / b if b1 else float("nan")
        # each trial against the one-rank run of the same trial (run just before it)
        eff = [100 * a / (np_ * x) for a, x in zip(runs[one]["trials"], r["trials"])] if one in runs else []
        scal.append((np_, t, sp, r, spb, eff))
        ratio = "%.2f" % (float(r["bytesMax"]) / share(scaleN, np_)) if r["bytesMax"] not in ("-", "") and np_ > 1 else "-"
        out.append("| %d | %.3f | %.3f | %s | %.2f | %.0f%% | %s | %s | %.3f | %.2f | %.0f%% | %s | %s | %d | %d | %s | %s | %s | %d |" % (
            np_, first(scaleN, "multilevelBSpline", np_), t, ", ".join("%.3f" % x for x in r["trials"]), sp, 100 * sp / np_,
            ", ".join("%.0f%%" % e for e in eff) or "-", "%.0f%%" % median(eff) if eff else "-",
            b, spb, 100 * spb / np_, r["bytes"], r["bytesMax"],
            share(scaleN, 1), share(scaleN, np_), ratio, r["messages"], r["messagesMax"], np_ - 1))
    # communication against mesh size: a rank's share of the boundary grows as
    # the faces' points, n^2; what a rank receives should not grow faster
    comm = sorted((np_, n) for (n, s, np_) in runs if s == "multilevelBSpline" and np_ > 1)
    growth = []
    if comm:
        out += ["", "## Communication of multilevelBSpline against mesh size", "",
                "| ranks | cells | control points | max bytes received by one rank per step | a rank's share of the boundary, bytes | max / share | gather-all bytes per rank | max messages received by one rank per step |",
                "|---|---|---|---|---|---|---|---|"]
        for np_, n in comm:
            r = runs[(n, "multilevelBSpline", np_)]
            out.append("| %d | %d | %d | %s | %d | %s | %d | %s |" % (
                np_, n**3, 2 * (n + 1)**2, r["bytesMax"], share(n, np_),
                "%.2f" % (float(r["bytesMax"]) / share(n, np_)) if r["bytesMax"] not in ("-", "") else "-", share(n, 1),
                r["messagesMax"]))
        for np_ in sorted({c[0] for c in comm}):
            ns = [n for p, n in comm if p == np_]
            if len(ns) >= 2:
                lo, hi = min(ns), max(ns)
                blo, bhi = float(runs[(lo, "multilevelBSpline", np_)]["bytesMax"]), float(runs[(hi, "multilevelBSpline", np_)]["bytesMax"])
                growth.append("%d ranks, %d to %d cells: a rank's share x%.1f, what it receives x%.1f" % (
                    np_, lo**3, hi**3, share(hi, np_) / share(lo, np_), bhi / blo))
        if growth:
            out += [""] + ["- " + g for g in growth]
    # growth: log-log fit of time and memory versus cells
    pts = [(n**3, solve(n, "multilevelBSpline", 1), runs[(n, "multilevelBSpline", 1)]["peakMB"])
           for n in sizes if (n, "multilevelBSpline", 1) in runs]
    def slope(xs, ys):
        lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
        mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
        den = sum((a - mx)**2 for a in lx)
        return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / den if den > 0 else float("nan")
    if len(pts) >= 2:
        out += ["", "Growth of multilevelBSpline (log-log fit over %d sizes): solve time ~ cells^%.2f, peak memory ~ cells^%.2f" % (
            len(pts), slope([p[0] for p in pts], [p[1] for p in pts]), slope([p[0] for p in pts], [p[2] for p in pts]))]
    if len(pts) >= 2 and plots:
        plt = pyplot()
        fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
        for s, mk in (("multilevelBSpline", "o"), (rigidLayers, "D"), ("displacementLaplacian", "s"), ("RBF", "^")):
            q = [(n**3, solve(n, s, 1), overRigid(n, s, 1), runs[(n, s, 1)]["peakMB"]) for n in sizes if (n, s, 1) in runs]
            if q:
                l = ax[0].loglog([a[0] for a in q], [a[1] for a in q], marker=mk, label=s + ": solve")
                if all(a[2] is not None for a in q):
                    ax[0].loglog([a[0] for a in q], [a[2] for a in q], marker=mk, ls="--", color=l[0].get_color(),
                                 label=s + ": step over rigid")
                ax[1].loglog([a[0] for a in q], [a[3] for a in q], marker=mk, label=s)
        rig = [(n**3, runs[(n, "rigid", 1)]["peakMB"]) for n in sizes if (n, "rigid", 1) in runs]
        if rig:
            ax[1].loglog([a[0] for a in rig], [a[1] for a in rig], marker="x", ls=":", color="gray", label="rigid motion (mesh alone)")
        ax[0].set_title("time per step [s] (median)"); ax[1].set_title("peak memory of the run [MB]")
        for a in ax: a.set_xlabel("cells"); a.grid(alpha=0.3, which="both"); a.legend(fontsize=7)
        fig.tight_layout(); fig.savefig(imgDir + "/bench-growth.png", dpi=110)
        written.append(imgDir + "/bench-growth.png")
    if scal and plots:
        plt = pyplot()
        cores = os.cpu_count() or 1
        fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
        ax[0].plot([s[0] for s in scal], [s[2] for s in scal], marker="o", label="median steps")
        ax[0].plot([s[0] for s in scal], [s[4] for s in scal], marker="s", label="fastest steps")
        tr = [(s[0], median(s[5]) * s[0] / 100) for s in scal if s[5]]
        if tr:
            ax[0].plot([x for x, y in tr], [y for x, y in tr], marker="^", label="each trial against its one-rank run (median)")
        ax[0].plot([s[0] for s in scal], [min(s[0], cores) for s in scal], "--", color="gray", label="ideal on %d cores" % cores)
        ax[0].set_title("speed-up of the solve, %d cells (beyond %d ranks oversubscribed)" % (scaleN**3, cores), fontsize=9)
        ax[0].set_xlabel("ranks"); ax[0].legend(fontsize=8); ax[0].grid(alpha=0.3)
        b = [(s[0], float(s[3]["bytesMax"])) for s in scal if s[3]["bytesMax"] not in ("-",) and s[0] > 1]
        if b:
            ax[1].plot([x for x, y in b], [y for x, y in b], marker="o", label="max bytes received by one rank per step")
            ax[1].axhline(share(scaleN, 1), ls="--", color="gray", label="gather-all, per rank")
            ax[1].plot([x for x, y in b], [share(scaleN, x) for x, y in b], ":", color="gray", label="a rank's share of the boundary")
            ax[1].set_xlabel("ranks"); ax[1].set_title("communication per step, %d cells" % scaleN**3, fontsize=9)
            ax[1].legend(fontsize=8); ax[1].grid(alpha=0.3)
        for np_ in sorted({c[0] for c in comm}):
            pts = [(n**3, float(runs[(n, "multilevelBSpline", np_)]["bytesMax"]), share(n, np_)) for p, n in comm if p == np_]
            if len(pts) < 2: continue
            l = ax[2].loglog([a for a, b, c in pts], [b for a, b, c in pts], marker="o", label="%d ranks: max received by one rank" % np_)
            ax[2].loglog([a for a, b, c in pts], [c for a, b, c in pts], ":", color=l[0].get_color(), label="%d ranks: a rank's share" % np_)
        ax[2].set_xlabel("cells"); ax[2].set_title("communication per step against mesh size [bytes]", fontsize=9)
        if ax[2].get_legend_handles_labels()[0]:
            ax[2].legend(fontsize=7)
        ax[2].grid(alpha=0.3, which="both")
        fig.tight_layout(); fig.savefig(imgDir + "/bench-scaling.png", dpi=110)
        written.append(imgDir + "/bench-scaling.png")
    open(mdPath, "w").write("\n".join(out) + "\n")
    print("\n".join(out))
    for path in written:
        print("wrote " + path)

def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    if sys.argv[1] in ("-h", "--help", "-help"):
        print(__doc__)
        return
    mode, args = sys.argv[1], sys.argv[2:]
    if mode == "record" and len(args) == 4:
        print(record(*args))
    elif mode == "tables" and len(args) == 5:
        tables(args[0], args[1], args[2], int(args[3]), args[4] == "1")
    else:
        sys.exit("report.py: expected 'record N METHOD RANKS CASE' or 'tables RUNS MD IMAGES SCALEN PLOTS'"
                 " (--help), got: %s" % " ".join(sys.argv[1:]))

if __name__ == "__main__":
    main()
