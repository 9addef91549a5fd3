#!/usr/bin/env python3
"""tutorials/compare's rows, table and plot (the morphers' quality on a
tutorial case against the motion's amplitude).

    compareReport.py row METHOD AMPLITUDE RUN STATUS
        one run's row, printed (tutorials/compare appends it to
        log/compare/<case>/rows.txt): "METHOD AMPLITUDE <the last row of
        RUN/postProcessing/morphQuality.dat, or none> | STATUS | <the largest
        height and angle change over all prism layers at that time, from
        morphQualityLayers.dat>"
    compareReport.py report CASE ROWS MD PNG AMPNAME
        the table of the runs ROWS lists (printed and written to MD: each
        method and amplitude, and the largest amplitude each method survives:
        run completed, no invalid cell) and the plot PNG of the measures
        against the amplitude (AMPNAME its axis label; matplotlib): of the
        meshes without invalid cells, and the invalid cells of every
        completed run
    compareReport.py label METHOD
        the method's name in the tables (S/on/I/L: "S, rigidLayers on, I level L")

A run's folder is ROWS's folder/<METHOD with each '/' as '-'>-<AMPLITUDE> (as
tutorials/compare makes it). The report takes the method, amplitude and
status from ROWS and each run's measures from its folder's
postProcessing/morphQuality.dat and morphQualityLayers.dat, by column name
(bin/bsmdata.py); the figures in a row are for reading.
"""
import os, sys
sys.dont_write_bytecode = True     # (no __pycache__ in the source tree)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bin"))
import bsmdata

# the columns of morphQuality.dat the table and plot use
QUALITY = ("maxNonOrth", "maxSkewness", "minDeterminant", "minVolRatio", "maxVolRatio", "nInvalid",
           "meanLayerHeightChange", "worstLayerHeightChange", "meanLayerAngleChange", "worstLayerAngleChange")

def runDir(rowsPath, method, amplitude):
    return os.path.join(os.path.dirname(os.path.abspath(rowsPath)), method.replace("/", "-") + "-" + amplitude)

def lastQuality(run):
    """The last row of the run's morphQuality.dat (None without one)"""
    return bsmdata.lastRow(os.path.join(run, "postProcessing", "morphQuality.dat"))

def allLayers(run, q):
    """The largest |worst height change| and |worst angle change| over the
    prism layers with cells at the time of morphQuality.dat's row q (None
    without morphQualityLayers.dat or such layers)"""
    path = os.path.join(run, "postProcessing", "morphQualityLayers.dat")
    if q is None or not os.path.exists(path):
        return None
    time = q[q.columns[0]]
    layers = [r for r in bsmdata.readTable(path) if r[r.columns[0]] == time and r["nCells"] > 0]
    if not layers:
        return None
    return (max(abs(r["worstHeightChange"]) for r in layers), max(abs(r["worstAngleChange"]) for r in layers))

def row(method, amplitude, run, status):
    q = lastQuality(run)
    layers = allLayers(run, q)
    return "%s %s %s | %s | %s" % (method, amplitude, q.line if q is not None else "none", status,
                                   "%.6g %.6g" % layers if layers else "")

def label(token):
    """S, S/on|off|sphere, S/on|off/I or S/on|off/I/L, each with an optional +rebase: the method's name
    in the tables (S/sphere: "rigidLayers on sphere only")"""
    rebase = token.endswith("+rebase")
    solver, layers, start, level = (token.removesuffix("+rebase").split("/") + ["", "", ""])[:4]
    layers = "on " + layers + " only" if layers not in ("", "on", "off") else layers
    return solver + (", rigidLayers " + layers if layers else "") + (", " + start if start else "") \
        + (" level " + level if level else "") + (", rebase on" if rebase else "")

def readRuns(rowsPath):
    """[(method label, amplitude, measures {name: value} or None, status)]"""
    runs = []
    for line in open(rowsPath):
        left, status, _ = line.rsplit("|", 2)
        method, amplitude = left.split()[:2]
        run = runDir(rowsPath, method, amplitude)
        q = lastQuality(run)
        m = None
        if q is not None and all(c in q for c in QUALITY):
            m = {c: q[c] for c in QUALITY}
            m["allLayersHeight"], m["allLayersAngle"] = allLayers(run, q) or (None, None)
        runs.append((label(method), float(amplitude), m, status.strip()))
    return runs

def report(case, rowsPath, mdPath, pngPath, ampName):
    runs = readRuns(rowsPath)
    solvers = list(dict.fromkeys(r[0] for r in runs))
    completed = lambda m, status: m is not None and status == "completed"
    ok = lambda m, status: completed(m, status) and m["nInvalid"] == 0
    out = ["| method | amplitude | run | max non-orth [deg] | max skewness | min determinant | volume ratio min / max "
           "| invalid cells | first-layer height change mean / worst | first-layer angle change mean / worst [deg] "
           "| all layers: largest height / angle change |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    small = lambda x, fmt: ("%.0e" % x) if x != 0 and abs(x) < 1e-3 else fmt % x
    for s, a, m, st in runs:
        if not completed(m, st):
            out.append("| %s | %g | %s | - | - | - | - | - | - | - | - |" % (s, a, st)); continue
        layersCol = "-" if m["allLayersHeight"] is None else "%s%% / %s" % (
            small(100*m["allLayersHeight"], "%.1f"), small(m["allLayersAngle"], "%.2f"))
        out.append("| %s | %g | %s | %.1f | %.2f | %.3g | %.3f / %.3f | %d | %s%% / %s%% | %s / %s | %s |" % (
            s, a, st, m["maxNonOrth"], m["maxSkewness"], m["minDeterminant"], m["minVolRatio"], m["maxVolRatio"],
            m["nInvalid"], small(100*m["meanLayerHeightChange"], "%.1f"), small(100*m["worstLayerHeightChange"], "%+.1f"),
            small(m["meanLayerAngleChange"], "%.2f"), small(m["worstLayerAngleChange"], "%+.2f"), layersCol))
    out += ["", "| method | largest amplitude survived (run completed, no invalid cell) |", "|---|---|"]
    for s in solvers:
        good = [a for t, a, m, st in runs if t == s and ok(m, st)]
        # survived means every amplitude up to it survived too
        amps = sorted(a for t, a, m, st in runs if t == s)
        best = None
        for a in amps:
            if a in good: best = a
            else: break
        out.append("| %s | %s |" % (s, "%g" % best if best is not None else "none of the amplitudes run"))
    open(mdPath, "w").write("\n".join(out) + "\n")
    print("\n".join(out))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = [("maxNonOrth", "max non-orthogonality [deg]"), ("maxSkewness", "max skewness"),
              ("minVolRatio", "min cell volume ratio"), ("worstLayerHeightChange", "|worst first-layer height change|"),
              ("worstLayerAngleChange", "|worst first-layer angle change| [deg]"), ("nInvalid", "invalid cells")]
    # (the measures of valid meshes only: a folded mesh's skewness or volume
    # ratio, thousands, would flatten every other curve; the invalid cells
    # of every completed run; each method in its own colour, every panel
    # over all amplitudes run)
    fig, axes = plt.subplots(2, 3, figsize=(13, 8))
    colour = {s: "C%d" % (i % 10) for i, s in enumerate(solvers)}
    amps = [r[1] for r in runs] or [0]
    pad = 0.05*(max(amps) - min(amps)) or 0.5
    lo, hi = min(amps) - pad, max(amps) + pad
    for ax, (key, title) in zip(axes.flat, panels):
        shown = completed if key == "nInvalid" else ok
        for s in solvers:
            pts = [(a, abs(m[key])) for t, a, m, st in runs if t == s and shown(m, st)]
            if pts:
                ax.plot(*zip(*pts), marker="o", color=colour[s])
        ax.set_title(title, fontsize=10); ax.set_xlabel(ampName)
        ax.grid(alpha=0.3)
        ax.set_xlim(lo, hi)
    fig.legend([plt.Line2D([], [], marker="o", color=colour[s]) for s in solvers], solvers,
               loc="lower center", ncol=3, fontsize=8)
    fig.suptitle("%s: morphing quality versus amplitude (meshes without invalid cells; invalid cells: every"
                 " completed run)" % case, fontsize=11)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(pngPath, dpi=110)
    print("compare: wrote", pngPath)

def main():
    mode, args = sys.argv[1], sys.argv[2:]
    if mode == "row":
        print(row(*args))
    elif mode == "report":
        report(*args)
    elif mode == "label":
        print(label(*args))
    else:
        sys.exit("compareReport.py: unknown mode %s (row, report, label)" % mode)

if __name__ == "__main__":
    main()
