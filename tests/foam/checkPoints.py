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
    checkPoints.py cyclic CASE box|sector|pipe|layers
                                             the points of a cyclic pair (tests/foam/Alltest.d/cyclic:
                                             the box's x faces, the sector's or the pipe's sides, those
                                             on the pipe's axis their own partners) have displacements
                                             equal through the pair's transform at every written time
    checkPoints.py tiltedSlip CASE [--planes-only]
                                             the sheared block of tests/foam/Alltest.d/tiltedSlip at
                                             time 1: the walls' points on their tilted planes, the
                                             first cell layer following the wall, the pushed face
                                             (--planes-only: the first alone)
    checkPoints.py wedge WEDGE TIME [PLANAR] [--tol T] [--axial]
                                             an axisymmetric case about the x axis (tests/foam/Alltest.d/
                                             wedge): no point moves across its meridian plane (those on
                                             the axis move along it), the front and back points of a
                                             meridian position move alike, and, given its planar twin (y as
                                             the radius, empty z), each moves along x and its radius as
                                             the twin's point at the same (x, r) moves along x and y
                                             (T of the domain, default 1e-12); --axial: a case whose
                                             conditions move everything along the axis (movingCone):
                                             no point moves radially either
    checkPoints.py coneLayers CASE TIME INNER [PLAIN] [--tol T]
                                             OpenFOAM's movingCone (tests/foam/Alltest.d/movingCone), its
                                             cone moved by (TIME 0 0): every point within INNER of one of
                                             the cone's points moved by exactly that (T of the domain,
                                             default 1e-12); in PLAIN (the same run without rigidLayers)
                                             they do not

Exit status 1 on any failed check; prints what it measured. Other test
scripts import check and failures from it (tests/foam/checkMorphQuality.py).
The points are read by bin/bsmdata.py (readPoints, readLabels, pointsAt,
comparePoints; also importable from here, as before).
"""
import os, sys
sys.dont_write_bytecode = True     # (no __pycache__ in the source tree)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bin"))
from bsmdata import readPoints, readLabels, pointsAt, comparePoints

failures = []
def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg)
    if not cond:
        failures.append(msg)

def cyclicPairs(case, kind):
    p0 = pointsAt(case, "constant")
    if kind in ("box", "layers"):   # left (x = 0) -> right (x = 1): translate by (1 0 0)
        onA = lambda p: abs(p[0]) < 1e-9
        T = lambda v: (v[0] + 1.0, v[1], v[2])
        R = lambda v: v
    else:                  # side0 (y = 0) -> side90 (x = 0): turn by 90 deg about z
        # (the pipe's sides meet on the axis: its points there are their own
        # partners, whose displacement the turn must leave as it is)
        onA = lambda p: abs(p[1]) < 1e-9 and p[0] > (0.5 if kind == "sector" else -1e-9)
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

def tiltedSlip(case, planesOnly=False):
    """tests/foam/Alltest.d/tiltedSlip: a block sheared so that its bottom and
    top are the planes z = 0.5 x and z = 1 + 0.5 x (slip walls), its left face
    pushed 0.1 along x, its right face fixed; time 1. planesOnly: only that
    the walls' points stay on their planes"""
    import math
    p0, p1 = pointsAt(case, "constant"), pointsAt(case, 1)
    n = (-0.5 / math.hypot(0.5, 1), 0.0, 1 / math.hypot(0.5, 1))
    # wall points stay on their planes (but those of the fixed faces, which win)
    off = max(abs(b[2] - 0.5 * b[0] - (1 if a[2] - 0.5 * a[0] > 0.5 else 0))
              for a, b in zip(p0, p1)
              if 0 < a[0] < 1 and (abs(a[2] - 0.5 * a[0]) < 1e-9 or abs(a[2] - 0.5 * a[0] - 1) < 1e-9))
    check(off < 1e-12, "bottom and top wall points stay on their planes (largest distance %.2e)" % off)
    if planesOnly:
        return
    # the first layer above the bottom wall follows it: its displacement normal
    # to the wall, relative to the wall point below. The pushed face's motion has
    # the normal component 0.1 (1 - x) |n_x| = 0.0447 (1 - x); projecting only the
    # wall points would leave all of it in the first layer. Mid-channel
    # (0.3 <= x <= 0.7, away from the pushed and the fixed face) at most 30% of
    # that may remain.
    key = lambda a: (round(a[0], 9), round(a[1], 9), round(a[2] - 0.5 * a[0], 9))
    index = {key(a): i for i, a in enumerate(p0)}
    prof = {}
    for i, a in enumerate(p0):
        x, y, h = key(a)
        if h == 0 and 0 < x < 1:
            j = index[(x, y, 0.1)]
            dd = [(p1[j][k] - p0[j][k]) - (p1[i][k] - a[k]) for k in range(3)]
            prof[x] = max(prof.get(x, 0.0), abs(sum(dd[k] * n[k] for k in range(3))))
    print("     first-layer normal displacement relative to the wall, by x: "
          + " ".join("%g:%.4f" % (x, v) for x, v in sorted(prof.items())))
    ratio = max(v / (0.1 * abs(n[0]) * (1 - x)) for x, v in prof.items() if 0.3 - 1e-9 <= x <= 0.7 + 1e-9)
    check(ratio < 0.3, "mid-channel first layer keeps %.0f%% of the normal motion projection alone would leave (< 30%%)" % (100 * ratio))
    moved = max(abs(b[0] - a[0]) for a, b in zip(p0, p1))
    check(abs(moved - 0.1) < 1e-12, "the left face moved 0.1 (largest x displacement %.3g)" % moved)

def wedge(wedgeCase, time, planarCase=None, tol=1e-12, axial=False):
    """Axisymmetric (about the x axis), and against planar: see the module's doc"""
    import math
    w0, w1 = pointsAt(wedgeCase, "constant"), pointsAt(wedgeCase, time)
    size = max(max(p[d] for p in w0) - min(p[d] for p in w0) for d in range(3))
    key = lambda x, r: (round(x, 8), round(r, 8))
    if planarCase:
        q0, q1 = pointsAt(planarCase, "constant"), pointsAt(planarCase, time)
        planar = {key(p[0], p[1]): i for i, p in enumerate(q0)}
    across = diff = radial = apart = 0.0
    matched = onAxis = 0
    pairs = {}
    for a, b in zip(w0, w1):
        r0 = math.hypot(a[1], a[2])
        d = [b[k] - a[k] for k in range(3)]
        if r0 > 1e-9:
            er = (0.0, a[1]/r0, a[2]/r0)
            et = (0.0, -a[2]/r0, a[1]/r0)
            across = max(across, abs(sum(d[k]*et[k] for k in range(3))))
            dr = sum(d[k]*er[k] for k in range(3))
        else:
            onAxis += 1
            across = max(across, math.hypot(d[1], d[2]))
            dr = 0.0
        radial = max(radial, abs(dr))
        other = pairs.setdefault(key(a[0], r0), (d[0], dr))
        apart = max(apart, abs(other[0] - d[0]), abs(other[1] - dr))
        if planarCase:
            j = planar.get(key(a[0], r0))
            if j is not None:
                matched += 1
                e = [q1[j][k] - q0[j][k] for k in range(2)]
                diff = max(diff, abs(d[0] - e[0]), abs(dr - e[1]))
    check(across <= tol*size, "no point moves across its meridian plane, the %d on the axis move along "
          "it (largest departure %.2e <= %g x domain %.3g)" % (onAxis, across, tol, size))
    check(apart <= tol*size, "the front and back points of each of the %d meridian positions move alike "
          "along x and the radius (largest difference %.2e <= %g x %.3g)" % (len(pairs), apart, tol, size))
    if axial:
        moved = max(abs(b[0] - a[0]) for a, b in zip(w0, w1))
        check(radial <= tol*size and moved > 1e-3*size, "every point moves along the axis only (largest "
              "radial part %.2e, largest axial %.3g)" % (radial, moved))
    else:
        check(radial > 1e-3*size, "the points moved radially (largest %.3g), the check is not vacuous" % radial)
    if planarCase:
        check(matched == len(w0), "every point has a planar twin at its (x, r) (%d of %d)" % (matched, len(w0)))
        check(diff <= tol*size, "each moves along x and its radius as its planar twin does: largest "
              "difference %.2e <= %g x %.3g" % (diff, tol, size))

def coneLayers(case, time, inner, plain=None, tol=1e-12):
    """movingCone's rigid zone moved with the cone: see the module's doc"""
    import numpy as np
    p0, p1 = np.array(pointsAt(case, "constant")), np.array(pointsAt(case, time))
    size = (p0.max(axis=0) - p0.min(axis=0)).max()
    x, r = p0[:, 0], np.hypot(p0[:, 1], p0[:, 2])
    # the cone (movingWall) in the meridian plane, in metres: x = -7 mm for
    # r up to 0.75, the slant to (-3.5, 2), and x = -3.5 mm down to the axis
    e = 1e-9
    cone = ((np.abs(x + 0.007) < e) & (r < 0.00075 + e)) \
        | ((np.abs(x + 0.0035) < e) & (r < 0.002 + e)) \
        | ((x > -0.007 - e) & (x < -0.0035 + e)
           & (np.abs((r - 0.00075)*3.5 - (x + 0.007)*1.25) < e))
    move = np.array([float(time), 0.0, 0.0])
    dist = np.sqrt(((p0[:, None, :] - p0[cone][None, :, :])**2).sum(axis=2)).min(axis=1)
    zone = (dist < inner) & ~cone
    err = np.abs(p1 - p0 - move).max(axis=1)
    check(cone.sum() > 0 and err[cone].max() <= tol*size, "the cone's %d points moved by %s (largest "
          "error %.2e <= %g x %.3g)" % (cone.sum(), move, err[cone].max(), tol, size))
    check(zone.sum() > 0 and err[zone].max() <= tol*size,
          "the %d points within %g of them moved with the cone: largest error %.2e <= %g x %.3g"
          % (zone.sum(), inner, err[zone].max(), tol, size))
    if plain:
        q1 = np.array(pointsAt(plain, time))
        off = np.abs(q1 - p0 - move).max(axis=1)[zone].max()
        check(off > 1e-3*size, "without rigidLayers they do not (largest departure %.3g)" % off)

def tolOption():
    """--tol T of the command line (default 1e-12)"""
    return float(sys.argv[sys.argv.index("--tol") + 1]) if "--tol" in sys.argv else 1e-12

def positionals():
    """The command line's arguments after the mode, less the options and --tol's value"""
    return [a for i, a in enumerate(sys.argv[2:], 2) if not a.startswith("--") and sys.argv[i - 1] != "--tol"]

def main():
    mode = sys.argv[1]
    if mode == "equal":
        a, b, time = sys.argv[2:5]
        tol = tolOption()
        c = comparePoints(a, b, time)
        check(c["nA"] == c["nB"], "same number of points (%d, %d)" % (c["nA"], c["nB"]))
        check(c["diff"] <= tol*c["size"], "largest difference %.3e <= %.1e x domain size %.3g"
              % (c["diff"], tol, c["size"]))
    elif mode == "at":
        case, time = sys.argv[2:4]
        x0, x1 = [float(v) for v in sys.argv[4:7]], [float(v) for v in sys.argv[7:10]]
        tol = tolOption()
        p0, p1 = pointsAt(case, "constant"), pointsAt(case, time)
        i = min(range(len(p0)), key=lambda k: sum((p0[k][d] - x0[d])**2 for d in range(3)))
        check(max(abs(p0[i][d] - x0[d]) for d in range(3)) < 1e-9, "a point at %s" % x0)
        err = max(abs(p1[i][d] - x1[d]) for d in range(3))
        check(err <= tol, "it moved to (%.12g %.12g %.12g), expected %s: error %.2e" % (p1[i] + (x1, err)))
    elif mode == "rigid":
        import numpy as np
        case, time, inner = sys.argv[2], sys.argv[3], float(sys.argv[4])
        twoD = "--2d" in sys.argv
        tol = tolOption()
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
    elif mode == "tiltedSlip":
        tiltedSlip(sys.argv[2], planesOnly="--planes-only" in sys.argv)
    elif mode == "wedge":
        args = positionals()
        tol = tolOption()
        wedge(*args[:3], tol=tol, axial="--axial" in sys.argv)
    elif mode == "coneLayers":
        args = positionals()
        tol = tolOption()
        coneLayers(args[0], args[1], float(args[2]), *args[3:4], tol=tol)
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
