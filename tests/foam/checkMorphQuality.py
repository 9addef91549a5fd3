#!/usr/bin/env python3
"""The hand-made meshes and the checks of tests/foam/Alltest.d/morphQuality
(a 2 x 1 x 1 block of 8 x 4 x 4 cells, graded in z, its bottom face a wall).

    checkMorphQuality.py checkerboard FILE
        write a manual decomposition (constant/cellDecomposition) putting
        neighbouring cells on the two ranks, as a checkerboard
    checkMorphQuality.py motions STRETCH SHEAR CASE [CASE ...]
        write the test's points at times 0.5 (undeformed), 1 (a rigid
        translation), 2 (one corner vertex pushed through its cell), 3 (a
        smooth non-rigid motion) and 4 (x -> x + SHEAR z^2, z -> z (1 + STRETCH z))
        into each case and, through decomposePar's pointProcAddressing, into
        its processor0 and processor1
    checkMorphQuality.py table SERIAL PARALLEL
        check morphQuality.dat (SERIAL, times 0.5 to 3) against what those
        motions should give, and PARALLEL's (2 ranks) against it
    checkMorphQuality.py layers STRETCH SHEAR DIR
        check morphQuality -layers 5 in DIR (serial) against the known
        change per layer, and the 2-rank runs in DIR-zSplit and
        DIR-checkerboard against serial
    checkMorphQuality.py strain STRETCH FILE
        check bin/strainAlongLine's output (FILE) up the line x = 1, y = 0.5
        at time 4 against the stretch's known strain

The tables are read by column name (bin/bsmdata.py); check() and the exit
status as in checkPoints.py (1 on any failed check).
"""
import math, os, re, sys
sys.dont_write_bytecode = True     # (no __pycache__ in the source tree)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bin"))
from checkPoints import check, failures
from bsmdata import readTable, byTime, pointsAt, readLabels

# the angle columns: compared on the scale of 90 deg, the others of 1
ANGLES = ("meanLayerAngleChange", "worstLayerAngleChange", "meanAngleChange", "worstAngleChange")
scaleOf = lambda column: 90 if column in ANGLES else 1

def checkerboard(path):
    # blockMesh numbers the (8 4 4) cells x fastest, then y, then z
    p = [(i + j + k) % 2 for k in range(4) for j in range(4) for i in range(8)]
    with open(path, "w") as f:
        f.write('FoamFile { version 2.0; format ascii; class labelList; location "constant"; object cellDecomposition; }\n')
        f.write("%d\n(\n%s\n)\n" % (len(p), "\n".join(str(v) for v in p)))

def writePoints(case, time, p):
    os.makedirs("%s/%s/polyMesh" % (case, time), exist_ok=True)
    with open("%s/%s/polyMesh/points" % (case, time), "w") as f:
        f.write('FoamFile { version 2.0; format ascii; class vectorField; location "%s/polyMesh"; object points; }\n' % time)
        f.write("%d\n(\n" % len(p))
        for x in p:
            f.write("(%.17g %.17g %.17g)\n" % x)
        f.write(")\n")

def motions(stretch, shear, cases):
    pts = pointsAt(cases[0], "constant")
    procs = [[readLabels("%s/processor%d/constant/polyMesh/pointProcAddressing" % (case, i)) for i in range(2)]
             for case in cases]
    def write(time, p):
        # the serial cases and, through decomposePar's addressing, the decomposed ones
        for case, addr in zip(cases, procs):
            writePoints(case, time, p)
            for i, a in enumerate(addr):
                writePoints("%s/processor%d" % (case, i), time, [p[k] for k in a])
    write(0.5, pts)
    write(1, [(x + 0.3, y - 0.2, z + 0.1) for x, y, z in pts])
    corner = pts.index((0.0, 0.0, 0.0))
    # the first cell's opposite corner: the smallest positive coordinates in each direction
    hx = min(x for x, y, z in pts if x > 0); hy = min(y for x, y, z in pts if y > 0); hz = min(z for x, y, z in pts if z > 0)
    p2 = list(pts); p2[corner] = (0.9*hx, 0.9*hy, 0.9*hz)
    write(2, p2)
    write(3, [(x, y, z + 0.05*z*math.sin(math.pi*x/2)) for x, y, z in pts])
    write(4, [(x + shear*z*z, y, z*(1 + stretch*z)) for x, y, z in pts])

def table(path):
    """morphQuality.dat: {time as written: row}"""
    return byTime(readTable(path))

def layers(path):
    """morphQualityLayers.dat: {time as written: {layer: row}}"""
    t = {}
    for r in readTable(path):
        t.setdefault(r.text[r.columns[0]], {})[int(r["layer"])] = r
    return t

def values(row, skip):
    """A row's columns but those in skip: [(column, value)]"""
    return [(c, row[c]) for c in row.columns[1:] if c not in skip]

def largestDifference(a, b, skip=()):
    """The largest relative difference of row b from row a over a's columns
    (on the scale of 1, of 90 deg for the angles); inf when b is missing"""
    if b is None:
        return float("inf")
    return max(abs(x - b[c]) / max(scaleOf(c), abs(x)) for c, x in values(a, skip))

def checkTable(serialPath, parallelPath):
    s, p = table(serialPath), table(parallelPath)
    u, t, inv, smooth = s["0.5"], s["1"], s["2"], s["3"]
    layerColumns = ("meanLayerHeightChange", "worstLayerHeightChange", "meanLayerAngleChange", "worstLayerAngleChange")
    check(u["maxNonOrth"] < 1e-6 and abs(u["maxSkewness"]) < 1e-9 and 0 < u["minDeterminant"] <= 1,
          "undeformed block: non-orthogonality %g deg, skewness %g, determinant %g"
          % (u["maxNonOrth"], u["maxSkewness"], u["minDeterminant"]))
    check(u["minVolRatio"] == 1 and u["maxVolRatio"] == 1 and u["nInvalid"] == 0 and all(u[c] == 0 for c in layerColumns),
          "undeformed: volume ratios 1, no invalid cell, no layer change")
    rel = [abs(t["minVolRatio"] - 1), abs(t["maxVolRatio"] - 1), abs(t["meanLayerHeightChange"]), abs(t["worstLayerHeightChange"]),
           abs(t["meanLayerAngleChange"]) / 90, abs(t["worstLayerAngleChange"]) / 90]
    check(max(rel) < 1e-12 and t["nInvalid"] == 0, "translated: largest relative change %.2e (< 1e-12), no invalid cell" % max(rel))
    check(abs(t["maxNonOrth"] - u["maxNonOrth"]) < 1e-6 and abs(t["maxSkewness"] - u["maxSkewness"]) < 1e-9
          and abs(t["minDeterminant"] - u["minDeterminant"]) < 1e-9,
          "translated: same absolute measures")
    check(inv["nInvalid"] == 1, "one vertex pushed through its cell: %d invalid cell(s), expected 1" % inv["nInvalid"])
    check(inv["minVolRatio"] < 0.5, "that cell's volume ratio %g < 0.5" % inv["minVolRatio"])
    # the smooth motion: bottom layer untouched (z = 0 stays) -> first-layer
    # heights change by the stretch of the first layer, 5% at most
    check(0 < smooth["worstLayerHeightChange"] <= 0.05 + 1e-12 and smooth["nInvalid"] == 0,
          "smooth stretch: worst first-layer height change %g in (0, 0.05], no invalid cell" % smooth["worstLayerHeightChange"])
    for time in s:
        a, b = s[time], p.get(time)
        # (on the scale of 1 for every column here; inf when the time is missing)
        worst = max(abs(x - b[c]) / max(1.0, abs(x)) for c, x in values(a, ())) if b is not None else float("inf")
        check(worst < 1e-12, "time %s: 2 ranks equal serial (largest relative difference %.2e)" % (time, worst))

def checkLayers(stretch, shear, d):
    serial = table(d + "/serial.dat")
    s = layers(d + "/postProcessing/morphQualityLayers.dat")
    check(open(d + "/postProcessing.withoutLayers").read().split() == ["morphQuality.dat"],
          "without -layers: no morphQualityLayers.dat")
    check(open(d + "/postProcessing/morphQuality.dat").read() == open(d + "/serial.dat").read(),
          "with -layers: morphQuality.dat as without")
    check(sorted(s) == sorted(serial) and all(sorted(s[t]) == [1, 2, 3, 4] for t in s),
          "layers 1..4 (of the 5 asked: the columns end at the top) at each of the times %s"
          % " ".join(sorted(s, key=float)))
    check("the columns on 1(bottom) end after 4 layers" in open(d + "/log.morphQuality.layers").read(),
          "the log says that the columns end after 4 layers")
    counts = sorted(set(tuple(int(s[t][k]["nCells"]) for k in range(1, 5)) for t in s))
    check(counts == [(32, 32, 32, 32)], "cells per layer %s, expected 32 32 32 32" % counts)
    # morphQualityLayers.dat's columns and morphQuality.dat's first-layer ones
    changes = ("meanHeightChange", "worstHeightChange", "meanAngleChange", "worstAngleChange")
    firstLayer = dict(zip(changes, ("meanLayerHeightChange", "worstLayerHeightChange",
                                    "meanLayerAngleChange", "worstLayerAngleChange")))
    check(all(s[t][1][c] == serial[t][firstLayer[c]] for t in s for c in changes),
          "layer 1 equals the first-layer columns of morphQuality.dat at every time")
    u = s["0.5"]
    check(all(u[k][c] == 0 for k in u for c in changes), "undeformed: no change in any layer")
    t = s["1"]
    rel = max(max(abs(t[k]["meanHeightChange"]), abs(t[k]["worstHeightChange"]),
                  abs(t[k]["meanAngleChange"])/90, abs(t[k]["worstAngleChange"])/90) for k in t)
    check(rel < 1e-12, "translated: largest relative change over the layers %.2e (< 1e-12)" % rel)
    inv = s["2"]
    check(abs(inv[1]["worstHeightChange"]) > 0.05 and all(inv[k][c] == 0 for k in (2, 3, 4) for c in changes),
          "corner vertex pushed: layer 1 changes (worst height change %g), layers 2-4 do not" % inv[1]["worstHeightChange"])
    # time 4: layer k between the levels z0 < z1 is a parallelepiped of height
    # (z1 - z0)(1 + stretch (z0 + z1)) whose top is shifted by shear (z1^2 - z0^2):
    # height change stretch (z0 + z1), angle atan(shear (z0 + z1)/(1 + stretch (z0 + z1)))
    # (the levels' points differ by rounding)
    zs = sorted(set(p[2] for p in pointsAt(d, "constant")))
    zs = [zs[0]] + [z for below, z in zip(zs, zs[1:]) if z - below > 1e-9]
    check(len(zs) == 5, "%d z levels, expected 5" % len(zs))
    err = 0
    for k in range(1, 5):
        w = zs[k - 1] + zs[k]
        h, a = stretch*w, math.degrees(math.atan(shear*w/(1 + stretch*w)))
        got = s["4"][k]
        print("     layer %d: height change %.15f (expected %.15f), angle change %.12f deg (expected %.12f)"
              % (k, got["worstHeightChange"], h, got["worstAngleChange"], a))
        err = max(err, abs(got["meanHeightChange"] - h), abs(got["worstHeightChange"] - h),
                  abs(got["meanAngleChange"] - a)/90, abs(got["worstAngleChange"] - a)/90)
    check(err < 1e-12, "stretch and shear: each layer's height and angle change as expected (largest error %.2e < 1e-12)" % err)
    # 2 ranks against serial: relative differences, on the scale of 1 for the
    # heights and the other measures, of 90 deg for the angles (acos of the
    # direction cosine amplifies the cell centres' rounding near an angle of 0: up
    # to 2e-12 deg on the checkerboard, in the first-layer columns as well)
    for split in ("zSplit", "checkerboard"):
        bnd = open("%s-%s/processor0/constant/polyMesh/boundary" % (d, split)).read()
        m = re.search(r"procBoundary0to1\s*\{[^}]*nFaces\s+(\d+)", bnd)
        expect = {"zSplit": 8*4, "checkerboard": 7*4*4 + 8*3*4 + 8*4*3}[split]
        check(m is not None and int(m.group(1)) == expect,
              "%s: %s faces between the ranks, expected %d" % (split, m and m.group(1), expect))
        p = layers("%s-%s/postProcessing/morphQualityLayers.dat" % (d, split))
        worst = max(largestDifference(s[t][k], p.get(t, {}).get(k), skip=("layer",)) for t in s for k in s[t])
        check(worst < 1e-12, "%s: 2 ranks' layers equal serial (largest relative difference %.2e)" % (split, worst))
        q = table("%s-%s/postProcessing/morphQuality.dat" % (d, split))
        worst = max(largestDifference(serial[t], q.get(t)) for t in serial)
        check(worst < 1e-12, "%s: 2 ranks' morphQuality.dat equals serial (largest relative difference %.2e)" % (split, worst))

def checkStrain(stretch, path):
    """bin/strainAlongLine's output up the line x = 1, y = 0.5 at time 4: the
    displacement along z is stretch z^2, so between points at z_a and z_b
    the strain is stretch (z_a + z_b), and from z = 0 to 1 stretch on average
    (the script prints positions and displacements to 1e-6, strains to 1e-4)"""
    lines = open(path).read().splitlines()
    rows = [l.split() for l in lines if not l.startswith("#")]
    check(len(rows) == 5, "strain along the line: %d points, expected 5" % len(rows))
    worst = max(abs(float(row[2]) - stretch*(float(prev[0]) + float(row[0]))) for prev, row in zip(rows, rows[1:]))
    check(worst < 1e-4, "strain between neighbours: largest error %.1e (< 1e-4)" % worst)
    worst = max(abs(float(row[1]) - stretch*float(row[0])**2) for row in rows)
    check(worst < 1e-6, "displacement along the line: largest error %.1e (< 1e-6)" % worst)
    mean = float(lines[-1].split(":")[1])
    check(abs(mean - stretch) < 1e-4, "mean strain %.4f, expected %g" % (mean, stretch))

def main():
    mode, args = sys.argv[1], sys.argv[2:]
    if mode == "checkerboard":
        checkerboard(args[0])
    elif mode == "motions":
        motions(float(args[0]), float(args[1]), args[2:])
    elif mode == "table":
        checkTable(args[0], args[1])
    elif mode == "layers":
        checkLayers(float(args[0]), float(args[1]), args[2])
    elif mode == "strain":
        checkStrain(float(args[0]), args[1])
    else:
        sys.exit("checkMorphQuality.py: unknown mode %s (checkerboard, motions, table, layers, strain)" % mode)
    return 1 if failures else 0

if __name__ == "__main__":
    sys.exit(main())
