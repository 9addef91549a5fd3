#!/usr/bin/env python3
"""Checks on a morphed hole-in-box case (tests/foam/morphCase.py).

    checkPoints.py motion CASE TIME [--2d]   prescribed/sliding/fixed points
    checkPoints.py equal A B TIME [--tol T]  the points of two cases agree within T x domain size
    checkPoints.py at CASE TIME X0 Y0 Z0 X1 Y1 Z1 [--tol T]
                                             the point initially at X0 Y0 Z0 is at X1 Y1 Z1
    checkPoints.py rigid CASE TIME INNER [--2d] [--tol T] [--slip-layers]
                                             the points within INNER of the hole's points moved
                                             with the hole's rigid motion (fitted to the hole);
                                             --slip-layers: and those within INNER of a sliding
                                             box face (x, y) keep their distance from it
    checkPoints.py cyclic CASE box|sector    the points of a cyclic pair (tests/foam/Alltest.d/cyclic:
                                             the box's x faces, the sector's sides) have displacements
                                             equal through the pair's transform at every written time

Exit status 1 on any failed check; prints what it measured. Other test scripts
import it for readPoints, readLabels, pointsAt and check (run from the project's
top folder: sys.path.insert(0, "tests/foam")).
"""
import re, sys

def readPoints(path):
    txt = open(path).read()
    body = txt[txt.index("(", txt.index("}")) :]
    nums = re.findall(r"\(([^()]+)\)", body)
    return [tuple(float(v) for v in s.split()) for s in nums]

def readLabels(path):
    """An ascii labelList (e.g. decomposePar's pointProcAddressing)"""
    txt = open(path).read()
    return [int(v) for v in txt[txt.index("(", txt.index("}")) + 1:txt.rindex(")")].split()]

def pointsAt(case, time):
    return readPoints("%s/%s/polyMesh/points" % (case, time) if time != "constant" else "%s/constant/polyMesh/points" % case)

failures = []
def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg)
    if not cond:
        failures.append(msg)

def cyclicPairs(case, kind):
    import os
    p0 = pointsAt(case, "constant")
    if kind == "box":      # left (x = 0) -> right (x = 1): translate by (1 0 0)
        onA = lambda p: abs(p[0]) < 1e-9
        T = lambda v: (v[0] + 1.0, v[1], v[2])
        R = lambda v: v
    else:                  # side0 (y = 0) -> side90 (x = 0): turn by 90 deg about z
        onA = lambda p: abs(p[1]) < 1e-9 and p[0] > 0.5
        T = R = lambda v: (-v[1], v[0], v[2])
    key = lambda p: tuple(round(x, 8) for x in p)
    index = {key(p): i for i, p in enumerate(p0)}
    A = [i for i, p in enumerate(p0) if onA(p)]
    B = [index.get(key(T(p0[i]))) for i in A]
    check(len(A) > 0 and None not in B, "%d point pairs matched through the transform" % len(A))
    if failures:
        return
    times = sorted((t for t in os.listdir(case) if t.replace(".", "", 1).isdigit() and float(t) > 0
                    and os.path.exists("%s/%s/polyMesh/points" % (case, t))), key=float)
    check(len(times) > 0, "written times with points: %s" % " ".join(times))
    for t in times:
        p1 = pointsAt(case, t)
        disp = lambda i: [p1[i][k] - p0[i][k] for k in range(3)]
        diff = moved = 0.0
        for a, b in zip(A, B):
            da, db = R(disp(a)), disp(b)
            diff = max(diff, max(abs(da[k] - db[k]) for k in range(3)))
            moved = max(moved, max(abs(x) for x in db))
        check(diff <= 1e-12, "time %s: paired displacements differ by at most %.3e (largest pair displacement %.3g)"
              % (t, diff, moved))
        check(moved > 1e-4, "time %s: the cyclic points moved (largest %.3g), the check is not vacuous" % (t, moved))

def main():
    mode = sys.argv[1]
    if mode == "equal":
        a, b, time = sys.argv[2:5]
        tol = float(sys.argv[sys.argv.index("--tol") + 1]) if "--tol" in sys.argv else 1e-12
        pa, pb = pointsAt(a, time), pointsAt(b, time)
        check(len(pa) == len(pb), "same number of points (%d, %d)" % (len(pa), len(pb)))
        p0 = pointsAt(a, "constant")
        size = max(max(p[d] for p in p0) - min(p[d] for p in p0) for d in range(3))
        diff = max(max(abs(x - y) for x, y in zip(p, q)) for p, q in zip(pa, pb))
        check(diff <= tol*size, "largest difference %.3e <= %.1e x domain size %.3g" % (diff, tol, size))
    elif mode == "at":
        case, time = sys.argv[2:4]
        x0, x1 = [float(v) for v in sys.argv[4:7]], [float(v) for v in sys.argv[7:10]]
        tol = float(sys.argv[sys.argv.index("--tol") + 1]) if "--tol" in sys.argv else 1e-12
        p0, p1 = pointsAt(case, "constant"), pointsAt(case, time)
        i = min(range(len(p0)), key=lambda k: sum((p0[k][d] - x0[d])**2 for d in range(3)))
        check(max(abs(p0[i][d] - x0[d]) for d in range(3)) < 1e-9, "a point at %s" % x0)
        err = max(abs(p1[i][d] - x1[d]) for d in range(3))
        check(err <= tol, "it moved to (%.12g %.12g %.12g), expected %s: error %.2e" % (p1[i] + (x1, err)))
    elif mode == "rigid":
        import numpy as np
        case, time, inner = sys.argv[2], sys.argv[3], float(sys.argv[4])
        twoD = "--2d" in sys.argv
        tol = float(sys.argv[sys.argv.index("--tol") + 1]) if "--tol" in sys.argv else 1e-12
        p0, p1 = np.array(pointsAt(case, "constant")), np.array(pointsAt(case, time))
        inf = np.abs(p0[:, :2 if twoD else 3] - 0.5).max(axis=1)
        hole = np.abs(inf - 0.15) < 1e-12
        # the hole's rigid motion x -> R x + t (Kabsch fit on its points)
        a, b = p0[hole], p1[hole]
        ca, cb = a.mean(axis=0), b.mean(axis=0)
        u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
        s = np.diag([1, 1, np.sign(np.linalg.det(vt.T @ u.T))])
        R = vt.T @ s @ u.T
        t = cb - R @ ca
        fit = np.abs(b - (a @ R.T + t)).max()
        angle = np.degrees(np.arccos(min(1.0, (np.trace(R) - 1)/2)))
        check(fit <= tol, "the hole moved rigidly (%d points, turned %.2f deg, fit error %.2e)"
              % (hole.sum(), angle, fit))
        dist = np.sqrt(((p0[:, None, :] - a[None, :, :])**2).sum(axis=2)).min(axis=1)
        zone = (dist < inner) & ~hole
        err = np.abs(p1[zone] - (p0[zone] @ R.T + t)).max(axis=1)
        check(zone.sum() > 0 and err.max() <= tol,
              "%d points within %g of the hole moved with it: largest error %.2e" % (zone.sum(), inner, err.max()))
        far = dist > 2*inner
        farErr = np.abs(p1[far] - (p0[far] @ R.T + t)).max()
        check(farErr > 1e-3, "points further out do not (largest departure %.3g)" % farErr)
        if "--slip-layers" in sys.argv:
            # nearest box face, when it is an x or y face (and clearly nearest)
            planes = np.stack([p0[:, 0], 1 - p0[:, 0], p0[:, 1], 1 - p0[:, 1]]
                              + ([] if twoD else [p0[:, 2], 1 - p0[:, 2]]), axis=1)
            near = planes.argmin(axis=1)
            srt = np.sort(planes, axis=1)
            slip = (srt[:, 0] < inner) & (near < 4) & (srt[:, 1] - srt[:, 0] > 1e-9) & (dist > inner)
            axis = near[slip]//2
            moved = np.abs(p1[slip, axis] - p0[slip, axis])
            check(slip.sum() > 0 and moved.max() <= tol,
                  "%d points within %g of a sliding face keep their distance from it: largest change %.2e"
                  % (slip.sum(), inner, moved.max()))
        if twoD:
            zErr = np.abs(p1[:, 2] - p0[:, 2]).max()
            check(zErr == 0.0, "empty-direction coordinates unchanged exactly (largest change %.3e)" % zErr)
    elif mode == "cyclic":
        cyclicPairs(sys.argv[2], sys.argv[3])
    else:
        case, time = sys.argv[2:4]
        twoD = "--2d" in sys.argv
        p0, p1 = pointsAt(case, "constant"), pointsAt(case, time)
        t = float(time)
        move = [0.06*t/3, 0.03*t/3, 0.0 if twoD else 0.015*t/3]
        hole = cube = slipErr = fixedErr = holeErr = zErr = 0.0
        nHole = nSlip = nFixed = 0
        for a, b in zip(p0, p1):
            d = [b[k] - a[k] for k in range(3)]
            inf = max(abs(a[0] - 0.5), abs(a[1] - 0.5))
            if not twoD:
                inf = max(inf, abs(a[2] - 0.5))
            if abs(inf - 0.15) < 1e-12:
                nHole += 1
                holeErr = max(holeErr, max(abs(d[k] - move[k]) for k in range(3)))
            if twoD:
                zErr = max(zErr, abs(d[2]))
                for k in (0,):   # x faces fixed in 2D
                    if a[k] in (0.0, 1.0):
                        nFixed += 1; fixedErr = max(fixedErr, max(abs(v) for v in d))
                if a[1] in (0.0, 1.0):
                    nSlip += 1; slipErr = max(slipErr, abs(d[1]))
            else:
                if a[2] in (0.0, 1.0):
                    nFixed += 1; fixedErr = max(fixedErr, max(abs(v) for v in d))
                for k in (0, 1):
                    if a[k] in (0.0, 1.0):
                        nSlip += 1; slipErr = max(slipErr, abs(d[k]))
        check(nHole > 0, "%d hole points found" % nHole)
        check(holeErr <= 1e-12, "hole points follow the prescribed displacement: error %.3e" % holeErr)
        check(nSlip > 0 and slipErr <= 1e-12, "%d slip points stay on their planes: %.3e" % (nSlip, slipErr))
        check(nFixed > 0 and fixedErr <= 1e-12, "%d fixed points stay: %.3e" % (nFixed, fixedErr))
        if twoD:
            check(zErr == 0.0, "empty-direction coordinates unchanged exactly (largest change %.3e)" % zErr)
        # the interior moved: the morph is not the identity
        moved = max(max(abs(b[k] - a[k]) for k in range(3)) for a, b in zip(p0, p1))
        check(moved > 0.01, "the mesh moved (largest displacement %.3g)" % moved)
    return 1 if failures else 0

if __name__ == "__main__":
    sys.exit(main())
