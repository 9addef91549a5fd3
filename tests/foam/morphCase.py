#!/usr/bin/env python3
"""Write a morphing test case: a unit box with a cube-shaped hole in the middle.

    morphCase.py DIR [--2d [--front-back symmetryPlane]] [--n N] [--solver NAME] [--pimple] [--np N]

3D: 26 hex blocks (a 3x3x3 block grid without its centre), N cells per block
edge. 2D: the 8 blocks around the centre square, one cell thick in z, front
and back 'empty'. The hole patch moves with uniformFixedValue (a table in
time); the box faces x and y slip, z is fixed (3D) - in 2D y slips, x is fixed.
--pimple adds U/p and the pimpleFoam settings (z: inlet/outlet in 3D).
"""
import argparse, os

ap = argparse.ArgumentParser()
ap.add_argument("dir")
ap.add_argument("--2d", dest="twoD", action="store_true")
ap.add_argument("--n", type=int, default=5)
ap.add_argument("--solver", default="multilevelBSpline")
ap.add_argument("--pimple", action="store_true")
ap.add_argument("--np", type=int, default=1)
ap.add_argument("--parts", type=int, nargs=3, default=None, metavar=("NX", "NY", "NZ"),
                help="hierarchical decomposition into NX x NY x NZ boxes (default: --np slabs along x)")
ap.add_argument("--coeff", nargs=2, action="append", default=[], metavar=("KEYWORD", "VALUE"),
                help="an entry of the solver's coefficients (repeatable)")
ap.add_argument("--end", type=int, default=3)
ap.add_argument("--merge-sides", action="store_true", help="one slip patch for the four x/y faces")
ap.add_argument("--free-sides", action="store_true",
                help="the x/y faces take the interpolated displacement (calculated) instead of slipping")
ap.add_argument("--move", type=float, default=0.06, help="x displacement of the hole at t=3")
ap.add_argument("--rotate", type=float, default=None, metavar="DEG",
                help="turn the hole rigidly about the z axis through (0.45 0.5 0.5) by DEG at the end time instead")
ap.add_argument("--rigid-layers", type=float, nargs=2, default=None, metavar=("INNER", "OUTER"),
                help="rigidLayers with these inner and outer distances")
ap.add_argument("--layer-patches", default="hole", help="rigidLayers' patches (default: hole)")
ap.add_argument("--front-back", default="empty", choices=("empty", "symmetryPlane"),
                help="--2d: the front and back patches' type (symmetryPlane: a 3D slab one cell thick)")
a = ap.parse_args()

X = [0.0, 0.35, 0.65, 1.0]
Z = X if not a.twoD else [0.0, 0.1]
nk = 3 if not a.twoD else 1
def vid(i, j, k): return (k*4 + j)*4 + i
verts = [(X[i], X[j], Z[k]) for k in range(len(Z)) for j in range(4) for i in range(4)]

patches = {n: [] for n in ["hole", "xMin", "xMax", "yMin", "yMax", "zMin", "zMax"]}
blocks = []
def face(c, axis, side):
    """corners of block c = (i,j,k) on face axis/side, outward ordering not needed (blockMesh sorts)"""
    i, j, k = c
    pts = []
    for dk in (0, 1):
        for dj in (0, 1):
            for di in (0, 1):
                d = (di, dj, dk)
                if d[axis] == side:
                    pts.append(vid(i + di, j + dj, k + dk))
    a0, a1, a2, a3 = pts
    return (a0, a1, a3, a2)
for k in range(nk):
    for j in range(3):
        for i in range(3):
            if (i, j) == (1, 1) and (a.twoD or k == 1):
                continue
            blocks.append((i, j, k))
bset = set(blocks)
for c in blocks:
    for axis in range(3 if not a.twoD else 2):
        for side in (0, 1):
            nb = list(c); nb[axis] += 1 if side else -1
            nb = tuple(nb)
            if nb in bset:
                continue
            out = nb[axis] < 0 or nb[axis] > (2 if axis < 2 or not a.twoD else 0)
            if not out:
                patches["hole"].append(face(c, axis, side))
            else:
                patches[["x", "y", "z"][axis] + ("Max" if side else "Min")].append(face(c, axis, side))
    if a.twoD:
        if a.front_back == "empty":
            patches.setdefault("frontAndBack", [])
            patches["frontAndBack"] += [face(c, 2, 0), face(c, 2, 1)]
        else:
            # (a symmetry plane is one plane: front and back apart)
            patches.setdefault("front", []).append(face(c, 2, 0))
            patches.setdefault("back", []).append(face(c, 2, 1))

if a.merge_sides and not a.twoD:
    patches["sides"] = sum((patches.pop(k) for k in ["xMin", "xMax", "yMin", "yMax"]), [])

os.makedirs(os.path.join(a.dir, "system"), exist_ok=True)
os.makedirs(os.path.join(a.dir, "constant"), exist_ok=True)
os.makedirs(os.path.join(a.dir, "0"), exist_ok=True)
def write(path, cls, obj, body):
    with open(os.path.join(a.dir, path), "w") as f:
        f.write("FoamFile { version 2.0; format ascii; class %s; object %s; }\n%s\n" % (cls, obj, body))

n = a.n
bm = "convertToMeters 1;\nvertices (\n%s\n);\nblocks (\n" % "\n".join("(%.17g %.17g %.17g)" % v for v in verts)
for (i, j, k) in blocks:
    h = [vid(i, j, k), vid(i+1, j, k), vid(i+1, j+1, k), vid(i, j+1, k),
         vid(i, j, k+1), vid(i+1, j, k+1), vid(i+1, j+1, k+1), vid(i, j+1, k+1)]
    bm += "hex (%s) (%d %d %d) simpleGrading (1 1 1)\n" % (" ".join(map(str, h)), n, n, 1 if a.twoD else n)
bm += ");\nedges ();\nboundary (\n"
ptype = {"frontAndBack": "empty", "front": a.front_back, "back": a.front_back, "hole": "wall"}
for name, faces in patches.items():
    if not faces:
        continue
    bm += "%s { type %s; faces (%s); }\n" % (name, ptype.get(name, "patch"),
                                             " ".join("(%d %d %d %d)" % f for f in faces))
bm += ");\n"
write("system/blockMeshDict", "dictionary", "blockMeshDict", bm)

app = "pimpleFoam" if a.pimple else "moveDynamicMesh"
write("system/controlDict", "dictionary", "controlDict",
      "application %s; startFrom latestTime; startTime 0; stopAt endTime; endTime %d; deltaT 1;\n"
      "writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 17;\n"
      "writeCompression off; timeFormat general; timePrecision 6; runTimeModifiable false;" % (app, a.end))
write("system/fvSchemes", "dictionary", "fvSchemes",
      "ddtSchemes { default Euler; } gradSchemes { default Gauss linear; }\n"
      "divSchemes { default none; div(phi,U) Gauss upwind; div((nuEff*dev2(T(grad(U))))) Gauss linear; }\n"
      "laplacianSchemes { default Gauss linear corrected; } interpolationSchemes { default linear; }\n"
      "snGradSchemes { default corrected; }")
write("system/fvSolution", "dictionary", "fvSolution",
      'solvers { "(p|pcorr)" { solver PCG; preconditioner DIC; tolerance 1e-8; relTol 0.01; }\n'
      '"(p|pcorr)Final" { solver PCG; preconditioner DIC; tolerance 1e-8; relTol 0; }\n'
      '"(U|UFinal)" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-8; relTol 0; }\n'
      '"cellDisplacement.*" { solver PCG; preconditioner DIC; tolerance 1e-10; relTol 0; } }\n'
      'PIMPLE { nOuterCorrectors 1; nCorrectors 2; nNonOrthogonalCorrectors 0; correctPhi yes; pRefCell 0; pRefValue 0; }')
write("system/decomposeParDict", "dictionary", "decomposeParDict",
      "numberOfSubdomains %d; method hierarchical; coeffs { n (%d %d %d); order xyz; }"
      % ((a.np,) + tuple(a.parts or (a.np, 1, 1))))

layers = ("rigidLayers { patches (%s); innerDistance %.17g; outerDistance %.17g; }"
          % ((a.layer_patches,) + tuple(a.rigid_layers)) if a.rigid_layers else "")
extra = " ".join("%s %s;" % (k, v) for k, v in a.coeff)
coeffs = {"multilevelBSpline": "multilevelBSplineCoeffs { tolerance 1e-10; %s %s }" % (layers, extra),
          "RBF": "RBFCoeffs { %s %s }" % (layers, extra),
          "displacementLaplacian": "displacementLaplacianCoeffs { diffusivity quadratic inverseDistance 1 (hole); }"}
libs = '("libbsplineMorph.so")' if a.solver != "displacementLaplacian" else '("libfvMotionSolvers.so")'
write("constant/dynamicMeshDict", "dictionary", "dynamicMeshDict",
      "dynamicFvMesh dynamicMotionSolverFvMesh;\nmotionSolverLibs %s;\nmotionSolver %s;\n%s" %
      (libs, a.solver, coeffs.get(a.solver, "")))

move = ("(%.17g 0.03 0)" if a.twoD else "(%.17g 0.03 0.015)") % a.move
bc = {"hole": "type uniformFixedValue; uniformValue table ((0 (0 0 0)) (3 %s));" % move,
      "xMin": "type slip;", "xMax": "type slip;", "yMin": "type slip;", "yMax": "type slip;",
      "zMin": "type fixedValue; value uniform (0 0 0);", "zMax": "type fixedValue; value uniform (0 0 0);",
      "frontAndBack": "type empty;", "front": "type symmetryPlane;", "back": "type symmetryPlane;",
      "sides": "type slip;"}
if a.rotate is not None:
    bc["hole"] = ("type solidBodyMotionDisplacement; solidBodyMotionFunction rotatingMotion; "
                  "rotatingMotionCoeffs { solidBodyMotionFunction rotatingMotion; origin (0.45 0.5 0.5); "
                  "axis (0 0 1); omega %.17g; } value uniform (0 0 0);" % (a.rotate*3.141592653589793/180/a.end))
if a.free_sides:
    for k in ["xMin", "xMax", "yMin", "yMax", "sides"]:
        bc[k] = "type calculated; value uniform (0 0 0);"
if a.twoD:
    bc["xMin"] = bc["xMax"] = "type fixedValue; value uniform (0 0 0);"
body = "dimensions [0 1 0 0 0 0 0];\ninternalField uniform (0 0 0);\nboundaryField {\n"
for name in patches:
    if patches[name]:
        body += "%s { %s }\n" % (name, bc[name])
write("0/pointDisplacement", "pointVectorField", "pointDisplacement", body + "}")
if a.solver == "displacementLaplacian":
    cd = body.replace("uniformFixedValue; uniformValue table ((0 (0 0 0)) (3 %s));" % move, "fixedValue; value uniform (0 0 0);")
    cd = cd.replace("type slip;", "type slip;")
    write("0/cellDisplacement", "volVectorField", "cellDisplacement",
          cd.replace("type fixedValue; value uniform (0 0 0);", "type cellMotion; value uniform (0 0 0);")
            .replace("type slip;", "type slip;") + "}")

if a.pimple:
    write("constant/transportProperties", "dictionary", "transportProperties", "transportModel Newtonian; nu 1e-3;")
    write("constant/turbulenceProperties", "dictionary", "turbulenceProperties", "simulationType laminar;")
    U = {"hole": "type movingWallVelocity; value uniform (0 0 0);", "zMin": "type fixedValue; value uniform (0 0 0.01);",
         "zMax": "type zeroGradient;", "frontAndBack": "type empty;"}
    P = {"zMax": "type fixedValue; value uniform 0;", "frontAndBack": "type empty;"}
    ub = "dimensions [0 1 -1 0 0 0 0];\ninternalField uniform (0 0 0.01);\nboundaryField {\n"
    pb = "dimensions [0 2 -2 0 0 0 0];\ninternalField uniform 0;\nboundaryField {\n"
    for name in patches:
        if patches[name]:
            ub += "%s { %s }\n" % (name, U.get(name, "type slip;"))
            pb += "%s { %s }\n" % (name, P.get(name, "type zeroGradient;"))
    write("0/U", "volVectorField", "U", ub + "}")
    write("0/p", "volScalarField", "p", pb + "}")
