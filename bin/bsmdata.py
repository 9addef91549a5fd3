"""bsplineMorph's data files, read from Python (the standard library alone).

    import os, sys
    sys.path.insert(0, os.path.join(PROJECT, "bin"))   # the folder of this file
    import bsmdata

Points (OpenFOAM ascii, as the tests and tutorials write them):
    readPoints(path)          [(x, y, z), ...] of a pointField file
    pointsAt(case, time)      the points of case/time/polyMesh (time "constant": the undeformed ones)
    readLabels(path)          an ascii labelList (e.g. decomposePar's pointProcAddressing)
    comparePoints(a, b, time) two cases' points at a time (serial against ranks, after
                              reconstructPar): the counts, the largest coordinate difference
                              and the domain size (of a's undeformed points)

Tables: the files whose columns a '# name name ...' line names (whitespace
separated; every '#' line is a comment, the last one before a row its header;
a header again where the columns change):
    postProcessing/morphQuality.dat         applications/morphQuality: time maxNonOrth
                                            maxSkewness ... nInvalid (first-layer columns)
    postProcessing/morphQualityLayers.dat   morphQuality -layers: time layer nCells ...
    postProcessing/<solver>/<startTime>/<solver>.dat
                                            the solvers (multilevelBSpline, RBF), one row per
                                            step: Time, the interpolation's figures (planMB,
                                            bytes, fit_s, ...; a re-fit's prefixed refit_),
                                            invalidCells check_s solve_s
    readTable(path)           the rows, each a Row: column name -> value
    lastRow(path)             the last row (None for a missing or empty file)
    byTime(rows)              {time as written: row}
    solverTable(case, solver) the solver's rows over all its start times ([] without a table)

Read columns by name (row["maxNonOrth"]), never by position: the programs may
add columns.
"""
import glob, os, re, struct, sys

# ---------------------------------------------------------------- points

def readPoints(path):
    """The points of a pointField file (after its FoamFile header), ascii or
    binary (double precision) as its header says"""
    if not os.path.isfile(path):
        raise SystemExit("%s: no points file %s" % (os.path.basename(sys.argv[0]), path))
    raw = open(path, "rb").read()
    end = raw.index(b"}")
    if re.search(rb"format\s+binary\s*;", raw[:end]):
        m = re.compile(rb"(\d+)\s*\(").search(raw, end + 1)   # (past the // * * * line)
        if not m:
            raise SystemExit("%s: %s: no point count after the header" % (os.path.basename(sys.argv[0]), path))
        n = int(m.group(1))
        v = struct.unpack_from("<%dd" % (3 * n), raw, m.end())
        return [v[3 * i:3 * i + 3] for i in range(n)]
    body = raw[raw.index(b"(", end):].decode()
    nums = re.findall(r"\(([^()]+)\)", body)
    return [tuple(float(v) for v in s.split()) for s in nums]

def readLabels(path):
    """An ascii labelList (e.g. decomposePar's pointProcAddressing)"""
    txt = open(path).read()
    return [int(v) for v in txt[txt.index("(", txt.index("}")) + 1:txt.rindex(")")].split()]

def pointsAt(case, time):
    """The points of case at time (a name or a number as OpenFOAM writes it; "constant": the undeformed ones)"""
    return readPoints("%s/%s/polyMesh/points" % (case, time) if time != "constant" else "%s/constant/polyMesh/points" % case)

def largestDifference(pa, pb):
    """The largest coordinate difference between two lists of points (over the
    points both have)"""
    return max(max(abs(x - y) for x, y in zip(p, q)) for p, q in zip(pa, pb))

def comparePoints(a, b, time):
    """Case b's points at time against case a's: dict(nA, nB, diff: the largest
    coordinate difference (over the points both have), size: the largest
    extent of a's undeformed points)"""
    pa, pb = pointsAt(a, time), pointsAt(b, time)
    p0 = pointsAt(a, "constant")
    size = max(max(p[d] for p in p0) - min(p[d] for p in p0) for d in range(3))
    return dict(nA=len(pa), nB=len(pb), diff=largestDifference(pa, pb), size=size)

# ---------------------------------------------------------------- tables

class Row(dict):
    """One row of a table: column name -> value (a float; the text as written
    where it is not a number). Also .columns (the names in the file's order),
    .text (column name -> the value as written) and .line (the row as written)."""
    def __init__(self, columns, words, line):
        super().__init__((c, _number(w)) for c, w in zip(columns, words))
        self.columns = list(columns)
        self.text = dict(zip(columns, words))
        self.line = line

def _number(word):
    try:
        return float(word)
    except ValueError:
        return word

def readTable(path):
    """The rows of a '# name ...' headed table (a list of Row)"""
    rows, header = [], None
    comment = None
    for n, line in enumerate(open(path), 1):
        line = line.rstrip("\n")
        if line.startswith("#"):
            comment = line[1:].split()
            continue
        words = line.split()
        if not words:
            continue
        if comment is not None:
            header, comment = comment, None
        if header is None or len(words) != len(header):
            raise ValueError("%s:%d: %d values, but the header before names %s" % (
                path, n, len(words), "no columns" if header is None else "%d: %s" % (len(header), " ".join(header))))
        rows.append(Row(header, words, line))
    return rows

def lastRow(path):
    """The table's last row; None when the file is missing or has no rows"""
    if not os.path.exists(path):
        return None
    rows = readTable(path)
    return rows[-1] if rows else None

def byTime(rows):
    """{the first column's text (the time as written, e.g. "0.5"): row}; a later row of the same time wins"""
    return {r.text[r.columns[0]]: r for r in rows}

def solverTable(case, solver):
    """The rows of postProcessing/<solver>/<startTime>/<solver>.dat of a case,
    every start time's (a restarted run's) in order; [] when there is none"""
    paths = glob.glob(os.path.join(case, "postProcessing", solver, "*", solver + ".dat"))
    rows = []
    for path in sorted(paths, key=lambda p: float(os.path.basename(os.path.dirname(p)))):
        rows += readTable(path)
    return rows
