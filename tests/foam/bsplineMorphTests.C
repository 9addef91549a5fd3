/*---------------------------------------------------------------------------*\
    bsplineMorph: the plugin inside OpenFOAM: the Pstream communicator passes
    the conformance suite; multilevelBSpline's dictionary is validated where
    it is read; bad displacements stop before the mesh moves.
\*---------------------------------------------------------------------------*/

#include <catch2/catch.hpp>

#include "foamTestCase.H"
#include "communicatorConformance.hpp"
#include "PstreamCommunicator.H"
#include "multilevelBSplineMotionSolver.H"
#include "rigidLayers.H"
#include "IStringStream.H"
#include "IOdictionary.H"
#include "fvMesh.H"
#include "volFields.H"
#include "primitiveMeshTools.H"
#include "vectorWidth.hpp"

#include <algorithm>
#include <limits>

using namespace Foam;

namespace
{
    using bsmTest::solverOf;

    autoPtr<motionSolver> bsplineSolver(const std::string& coeffs)
    {
        return solverOf("multilevelBSpline", coeffs);
    }

    // A solve with every wall point fixed at zero leaves the mesh where it is
    void requireUnmoved(motionSolver& solver, const scalar tol)
    {
        solver.solve();
        const pointField p1(solver.curPoints());
        const pointField& p0 = bsmTest::mesh().points();
        forAll(p0, pointi)
        {
            REQUIRE(mag(p1[pointi] - p0[pointi]) <= tol);
        }
    }

    // Walls displaced by the affine field a + B x: every point of the mesh
    // moves by exactly a + B x (to tol), serial or on any number of ranks
    void requireAffine(motionSolver& solver, const scalar tol)
    {
        const vector a(0.05, -0.02, 0.03);
        const tensor B(0.02, -0.1, 0.03, 0.1, 0.01, -0.04, -0.02, 0.05, 0.03);
        displacementMotionSolver& dms = refCast<displacementMotionSolver>(solver);
        const label patchi = bsmTest::mesh().boundaryMesh().findPatchID("walls");
        REQUIRE(patchi >= 0);
        pointPatchVectorField& pf = dms.pointDisplacement().boundaryFieldRef()[patchi];
        const vectorField x(pf.patch().localPoints());
        pf == vectorField(a + (B & x));
        solver.solve();
        const pointField p1(solver.curPoints());
        const pointField& p0 = bsmTest::mesh().points();
        scalar worst = 0;
        forAll(p0, pointi)
        {
            worst = max(worst, mag(p1[pointi] - (p0[pointi] + a + (B & p0[pointi]))));
        }
        worst = returnReduce(worst, maxOp<scalar>());
        INFO("largest departure from x + a + B x: " << worst);
        CHECK(worst <= tol);
        // (and the points moved: a displacement of about 0.1)
        CHECK(returnReduce(max(mag(p1 - p0)), maxOp<scalar>()) > 0.05);
    }

    std::string errorOf(const std::string& coeffs, const std::string& type = "multilevelBSpline")
    {
        try
        {
            solverOf(type, coeffs);
        }
        catch (const Foam::error& err)
        {
            return err.message();
        }
        return "no error";
    }
}


TEST_CASE("PstreamCommunicator passes the communicator conformance suite", "[foam][conformance]")
{
    const PstreamCommunicator comm;
    CHECK(comm.size() == (Pstream::parRun() ? Pstream::nProcs() : 1));
    bsmTest::communicatorConformance(comm);
}


TEST_CASE("multilevelBSpline: the defaults give a working solver", "[foam][bsplineMorph]")
{
    autoPtr<motionSolver> solver = bsplineSolver("");
    REQUIRE(solver.valid());
    CHECK(solver->type() == "multilevelBSpline");
    requireUnmoved(solver.ref(), 0);
}


namespace
{
    // A copy of the mesh with these points (its own geometry: cell centres,
    // volumes, face areas), registered nowhere
    autoPtr<polyMesh> movedCopy(const polyMesh& mesh, const pointField& p)
    {
        return autoPtr<polyMesh>::New
        (
            IOobject("movedCopy", mesh.time().constant(), mesh.time(),
                IOobject::NO_READ, IOobject::NO_WRITE, false),
            pointField(p),
            faceList(mesh.faces()),
            labelList(mesh.faceOwner()),
            labelList(mesh.faceNeighbour()),
            false
        );
    }

    // checkMesh's own verdict on the mesh's cells with these points: a copy
    // of the mesh moved to them (its cell centres and volumes), its cell
    // volumes below VSMALL and the face pyramids against its centres below
    // -SMALL that checkCellVolumes and checkFacePyramids report (each
    // pyramid on its own side), and those below -1e-10 of their scale
    // |S| |h| / 3 (invertedCellCheck::turnedFraction: a face turned in a
    // cell too small for SMALL); the number of cells with any (all ranks).
    // Of copy, the mesh moved by movedCopy
    label checkMeshInvalidCells(const polyMesh& mesh, const polyMesh& copy)
    {
        const pointField& p = copy.points();
        boolList invalid(mesh.nCells(), false);
        forAll(copy.cellVolumes(), celli)
        {
            invalid[celli] = copy.cellVolumes()[celli] < VSMALL;
        }
        scalarField ownPyrVol, neiPyrVol;
        const vectorField& cc = copy.cellCentres();
        primitiveMeshTools::facePyramidVolume(copy, p, cc, ownPyrVol, neiPyrVol);
        const vectorField& S = copy.faceAreas();
        const vectorField& fc = copy.faceCentres();
        const scalar eps = invertedCellCheck::turnedFraction/3;
        forAll(ownPyrVol, facei)
        {
            const label o = mesh.faceOwner()[facei];
            const scalar scale = eps*mag(S[facei])*mag(cc[o] - fc[facei]);
            if (ownPyrVol[facei] < -SMALL || ownPyrVol[facei] < -scale) invalid[o] = true;
        }
        forAll(neiPyrVol, facei)
        {
            const label n = mesh.faceNeighbour()[facei];
            const scalar scale = eps*mag(S[facei])*mag(cc[n] - fc[facei]);
            if (neiPyrVol[facei] < -SMALL || neiPyrVol[facei] < -scale) invalid[n] = true;
        }
        return returnReduce(label(std::count(invalid.begin(), invalid.end(), true)), sumOp<label>());
    }

    // The same, for the mesh moved to p
    label checkMeshInvalidCells(const polyMesh& mesh, const pointField& p)
    {
        return checkMeshInvalidCells(mesh, movedCopy(mesh, p)());
    }
}


TEST_CASE("An affine motion of the walls moves every point by exactly that motion", "[foam][bsplineMorph][rbf]")
{
    // multilevelBSpline's affine start (the default) reproduces it, the
    // levels have nothing left to fit; RBF's linear polynomial reproduces it
    // to the solves' round-off
    SECTION("multilevelBSpline")
    {
        autoPtr<motionSolver> solver = bsplineSolver("");
        requireAffine(solver.ref(), 1e-13);
    }
    SECTION("multilevelBSpline over a thin-plate spline")
    {
        // (the spline's linear polynomial holds the motion, to its solve's
        // round-off; the B-splines reproduce its samples exactly)
        autoPtr<motionSolver> solver = bsplineSolver
        (
            "initialApproximation thinPlateSpline; thinPlateSplineCoeffs { grid 4; level 2; }"
        );
        requireAffine(solver.ref(), 1e-10);
    }
    SECTION("RBF")
    {
        autoPtr<motionSolver> solver = solverOf("RBF", "");
        requireAffine(solver.ref(), 1e-10);
    }
}


TEST_CASE("The inverted-cell check counts the cells checkMesh calls an error", "[foam][bsplineMorph]")
{
    const fvMesh& mesh = bsmTest::mesh();
    const pointField& p0 = mesh.points();
    const label nCells = bsmTest::caseCells[0]*bsmTest::caseCells[1]*bsmTest::caseCells[2];
    const bool hexKernel = GENERATE(true, false);
    INFO("hexahedra " << (hexKernel ? "in vector lanes" : "as general cells"));
    const invertedCellCheck check(mesh, hexKernel);

    SECTION("the undisturbed mesh and a rigid motion have none")
    {
        const tensor R(0, -1, 0, 1, 0, 0, 0, 0, 1);
        const pointField p((R & p0) + vector(3, -2, 1));
        const invertedCellCheck::result r = check.check(p);
        CHECK(r.nInvalid == 0);
        CHECK(r.nJudged == 0);
        CHECK(check.check(p0).nInvalid == 0);
    }

    SECTION("the box folded about a plane of points: the mirrored half")
    {
        // Every face stays planar; the cells below x = 1/2 are mirrored
        // (negative volume), the others sheared and stretched only
        const tensor A(1.2, 0.3, 0, 0, 0.9, 0.2, 0.1, 0, 1.1);
        pointField p(p0.size());
        forAll(p0, pointi)
        {
            vector x = p0[pointi];
            x.x() = mag(x.x() - 0.5);
            p[pointi] = (A & x) + vector(0.3, -0.2, 0.1);
        }
        const invertedCellCheck::result r = check.check(p);
        CHECK(r.nInvalid == nCells/2);
        CHECK(r.nNonPositive == nCells/2);
        CHECK(r.nFolded == 0);
        CHECK(r.nInvalid == checkMeshInvalidCells(mesh, p));
        CHECK(r.where.max().x() < 0.3 + 1.2*0.5 + 0.3 + 1e-9);
    }

    SECTION("a layer of cells flattened to no volume: reported where it is")
    {
        // The points at x = 0.5 moved onto x = 0.4 (to round-off): the
        // volume-weighted centres of those cells, divided by volumes near
        // zero, lie anywhere; the report gives the means of their points
        pointField p(p0);
        forAll(p, pointi)
        {
            if (mag(p0[pointi].x() - 0.5) < 1e-9)
            {
                p[pointi].x() = 0.4 + 1e-15*p0[pointi].y()*(1 - p0[pointi].z());
            }
        }
        const invertedCellCheck::result r = check.check(p);
        // (of the flattened layer's 48 cells, those whose round-off volume
        // or pyramids checkMesh calls an error)
        CHECK(r.nInvalid > 0);
        CHECK(r.nInvalid <= bsmTest::caseCells[1]*bsmTest::caseCells[2]);
        CHECK(r.nInvalid == checkMeshInvalidCells(mesh, p));
        CHECK(mag(r.where.min().x() - 0.4) < 1e-9);
        CHECK(mag(r.where.max().x() - 0.4) < 1e-9);
        CHECK(r.where.min().y() > 0);
        CHECK(r.where.max().y() < 1);
        // This rank's invalid cells: those of the flattened layer
        CHECK(returnReduce(r.cells.size(), sumOp<label>()) == r.nInvalid);
        for (const label celli : r.cells)
        {
            CHECK(mag(mesh.cellCentres()[celli].x() - 0.45) < 0.051);
        }
    }

    SECTION("one point pushed into its neighbours: folded cells of positive volume")
    {
        // The mesh point at (0.3, 0.5, 0.5) pushed along (1, 1, 1) by a
        // fraction of a cell's diagonal (0.1 x 0.125 x 0.1667): its eight
        // cells fold before any turns inside out
        const vector h(0.1, 0.125, 1.0/6);
        label foldedOnly = 0, shrunkFolded = 0;
        for (const scalar s : {0.1, 0.3, 0.5, 0.7, 0.9, 1.2})
        {
            pointField p(p0);
            forAll(p, pointi)
            {
                if (mag(p0[pointi] - vector(0.3, 0.5, 0.5)) < 1e-9)
                {
                    p[pointi] += s*h;
                }
            }
            const invertedCellCheck::result r = check.check(p);
            const label expected = checkMeshInvalidCells(mesh, p);
            // (hexahedra two at a time: the same verdicts)
            const bool wide = mba::useWideVectors(false);
            const invertedCellCheck::result narrow = check.check(p);
            mba::useWideVectors(wide);
            CHECK(narrow.nInvalid == r.nInvalid);
            CHECK(narrow.nJudged == r.nJudged);
            INFO("push " << s << ": " << r.nInvalid << " invalid (" << r.nNonPositive
                << " non-positive, " << r.nFolded << " folded), checkMesh " << expected);
            CHECK(r.nInvalid == expected);
            CHECK(r.nInvalid == r.nNonPositive + r.nFolded);
            if (r.nFolded > 0 && r.nNonPositive == 0) ++foldedOnly;
            if (r.nInvalid > 0)
            {
                // (the invalid cells' centres lie next to the pushed point)
                CHECK(mag(r.where.max() - (point(0.3, 0.5, 0.5) + s*h)) < mag(h));
                CHECK(mag(r.where.min() - (point(0.3, 0.5, 0.5) + s*h)) < mag(h));
            }
            // The same mesh 1e5 times smaller (cells of 2e-18 m^3, whose
            // pyramids are all within checkMesh's absolute SMALL): the same
            // cells fold
            const pointField small(1e-5*p);
            const invertedCellCheck::result rSmall = check.check(small);
            CHECK(rSmall.nInvalid == r.nInvalid);
            CHECK(rSmall.nFolded == r.nFolded);
            CHECK(rSmall.nInvalid == checkMeshInvalidCells(mesh, small));
            if (r.nFolded > 0 && r.nNonPositive == 0) shrunkFolded += rSmall.nFolded;
        }
        // Some pushes fold cells that keep a positive volume: the check
        // that looked at volumes only let these through; and also in the
        // shrunk mesh, where only the pyramids' own scale tells
        CHECK(foldedOnly > 0);
        CHECK(shrunkFolded > 0);
    }

    SECTION("every face checkMesh calls a non-orthogonality error has a flagged cell")
    {
        // Faces need no check of their own: d . S is three times the sum of
        // the face's two pyramids, so a face at 90 deg or more has one that
        // turned. Every point moved by a pseudo-random fraction of a cell
        // (a function of its position: the same on every rank), seeded
        const vector h(0.1, 0.125, 1.0/6);
        const auto noise = [](const point& x, const scalar k)
        {
            const scalar v = std::sin(x & vector(12.9898*k, 78.233*k, 37.719*k))*43758.5453;
            return 2*(v - std::floor(v)) - 1;
        };
        label nErrorFaces = 0;
        for (const scalar a : {0.2, 0.35, 0.5, 0.65, 0.8})
        {
            pointField p(p0);
            forAll(p, pointi)
            {
                const point& x = p0[pointi];
                p[pointi] += a*vector(h.x()*noise(x, 1), h.y()*noise(x, 2), h.z()*noise(x, 3));
            }
            const invertedCellCheck::result r = check.check(p);
            const autoPtr<polyMesh> moved = movedCopy(mesh, p);
            const polyMesh& copy = moved();
            CHECK(r.nInvalid == checkMeshInvalidCells(mesh, copy));
            const scalarField ortho
            (
                primitiveMeshTools::faceOrthogonality(copy, copy.faceAreas(), copy.cellCentres())
            );
            boolList flagged(mesh.nCells(), false);
            UIndirectList<bool>(flagged, r.cells) = true;
            label nHere = 0, nMissed = 0;
            forAll(ortho, facei)
            {
                if (ortho[facei] <= SMALL)    // checkMesh's "non-orthogonality error"
                {
                    ++nHere;
                    nMissed +=
                        !flagged[mesh.faceOwner()[facei]] && !flagged[mesh.faceNeighbour()[facei]];
                }
            }
            INFO("noise " << a << " of a cell: " << r.nInvalid << " invalid cells, "
                << nHere << " faces at 90 deg or more on this rank");
            CHECK(nMissed == 0);
            nErrorFaces += returnReduce(nHere, sumOp<label>());
        }
        // (the noise reaches such faces: the check above is not vacuous)
        CHECK(nErrorFaces > 0);
    }
}


TEST_CASE("multilevelBSpline: invalid keyword values name the entry", "[foam][bsplineMorph][errors]")
{
    using Catch::Matchers::Contains;
    // (out of range: the entry, its value and the allowed range; a word
    // that is not one of its values: the entry, the word, the valid ones)
    CHECK_THAT(errorOf("tolerance -1;"), Contains("tolerance") && Contains("-1") && Contains("at least 0"));
    CHECK_THAT(errorOf("maxLevels 0;"), Contains("maxLevels") && Contains("from 1 to 30"));
    CHECK_THAT(errorOf("maxLevels 100;"), Contains("'maxLevels' is 100") && Contains("from 1 to 30") && Contains("default 12"));
    CHECK_THAT(errorOf("initialGrid 0;"), Contains("initialGrid") && Contains("from 1 to 1048576"));
    CHECK_THAT(errorOf("bucketTiles 0;"), Contains("bucketTiles") && Contains("at least 1"));
    const std::string approx = errorOf("initialApproximation quadratic;");
    CHECK_THAT(approx, Contains("'initialApproximation' is 'quadratic'") && Contains("affine") && Contains("none")
        && Contains("thinPlateSpline") && Contains("default affine"));
    const std::string tps = "initialApproximation thinPlateSpline; thinPlateSplineCoeffs ";
    CHECK_THAT(errorOf(tps + "{ grid 0; }"), Contains("'grid' is 0") && Contains("from 1 to 32") && Contains("default 8"));
    CHECK_THAT(errorOf(tps + "{ level 6; }"), Contains("'level' is 6") && Contains("from 0 to 5") && Contains("default 4"));
    CHECK(errorOf(tps + "{ grid 6; level 3; }") == "no error");
    CHECK_THAT(errorOf(tps + "3;"), Contains("thinPlateSplineCoeffs must be a dictionary { grid ...; level ...; }"));
    const std::string inverted = errorOf("invertedCells maybe;");
    CHECK_THAT(inverted, Contains("'invertedCells' is 'maybe'") && Contains("fatal") && Contains("warn")
        && Contains("default fatal"));
    CHECK_THAT(errorOf("curvedSlipAngle 90;"), Contains("'curvedSlipAngle' is 90") && Contains("from 0 to 89")
        && Contains("default 30"));
    CHECK(errorOf("curvedSlipAngle 45;") == "no error");
    CHECK_THAT(errorOf("relativeTolerance perhaps;"), Contains("perhaps"));
    CHECK_THAT(errorOf("rebase perhaps;"), Contains("perhaps") && Contains("on/off"));
    CHECK(errorOf("rebase on;") == "no error");
    const std::string exchange = errorOf("exchange sideways;");
    CHECK_THAT(exchange, Contains("'exchange' is 'sideways'") && Contains("automatic") && Contains("direct")
        && Contains("chunked") && Contains("tree"));
    CHECK(errorOf("tolerance 1e-8; maxLevels 8; initialGrid 2; initialApproximation none;") == "no error");
}


TEST_CASE("multilevelBSpline: a NaN or huge displacement stops before the mesh moves", "[foam][bsplineMorph][errors]")
{
    // (1e300: its square overflows; anything over 1e8 times the mesh's size
    // is refused with it)
    const scalar value = GENERATE(std::numeric_limits<scalar>::quiet_NaN(), 1e300, 1e9);
    autoPtr<motionSolver> solver = bsplineSolver("");
    displacementMotionSolver& dms = refCast<displacementMotionSolver>(solver.ref());
    const label patchi = bsmTest::mesh().boundaryMesh().findPatchID("walls");
    REQUIRE(patchi >= 0);
    pointPatchVectorField& pf = dms.pointDisplacement().boundaryFieldRef()[patchi];
    vectorField bad(pf.size(), vector(0.1, 0, 0));
    if (bad.size())
    {
        bad[0].x() = value;
    }
    pf == bad;
    try
    {
        solver->solve();
        FAIL("no error raised");
    }
    catch (const Foam::error& err)
    {
        CHECK_THAT(std::string(err.message()), Catch::Matchers::Contains("non-finite (NaN or Inf) or huge") && Catch::Matchers::Contains("walls"));
    }
}


TEST_CASE("RBF: invalid keyword values name the entry and the choices", "[foam][rbf][errors]")
{
    using Catch::Matchers::Contains;
    const std::string function = errorOf("function gaussian;", "RBF");
    CHECK_THAT(function, Contains("'function' is 'gaussian'") && Contains("inverseMultiquadric")
        && Contains("thinPlateSpline") && Contains("wendlandC2"));
    CHECK_THAT(errorOf("shapeParameter 0;", "RBF"), Contains("shapeParameter"));
    CHECK_THAT(errorOf("supportRadius -1;", "RBF"), Contains("supportRadius"));
    CHECK_THAT(errorOf("maxPoints 0;", "RBF"), Contains("maxPoints") && Contains("at least 1") && Contains("default 20000"));
    CHECK_THAT(errorOf("greedyTolerance -1;", "RBF"), Contains("greedyTolerance"));
    CHECK_THAT(errorOf("greedyBatch 0;", "RBF"), Contains("greedyBatch"));
    CHECK_THAT(errorOf("function thinPlateSpline; polynomial false;", "RBF"),
        Contains("thinPlateSpline") && Contains("polynomial"));
    CHECK_THAT(errorOf("invertedCells maybe;", "RBF"), Contains("'invertedCells' is 'maybe'"));
    CHECK_THAT(errorOf("rebase perhaps;", "RBF"), Contains("perhaps") && Contains("on/off"));
    CHECK_THAT(errorOf("curvedSlipAngle -1;", "RBF"), Contains("'curvedSlipAngle' is -1") && Contains("from 0 to 89"));
    CHECK(errorOf("function wendlandC2; supportRadius 2; polynomial false;", "RBF") == "no error");
}


TEST_CASE("RBF: the defaults keep a mesh whose walls are fixed at zero", "[foam][rbf]")
{
    autoPtr<motionSolver> solver = solverOf("RBF", "");
    REQUIRE(solver.valid());
    CHECK(solver->type() == "RBF");
    requireUnmoved(solver.ref(), 1e-12);
}


TEST_CASE("rigidLayers: bad input names the entry and the valid choices", "[foam][rigidLayers][errors]")
{
    using Catch::Matchers::Contains;
    const std::string unknown =
        errorOf("rigidLayers { patches (walls sphere); innerDistance 0.1; outerDistance 0.2; }");
    CHECK_THAT(unknown, Contains("patches") && Contains("sphere") && Contains("(walls)"));
    CHECK_THAT
    (
        errorOf("rigidLayers { patches (); innerDistance 0.1; outerDistance 0.2; }"),
        Contains("patches: the list is empty") && Contains("(walls)")
    );
    // A group names its patches (wall patches are in the group 'wall')
    CHECK(errorOf("rigidLayers { patches (wall); innerDistance 0.1; outerDistance 0.2; }") == "no error");
    CHECK(errorOf("rigidLayers { patches (walls); innerDistance 0.1; outerDistance 0.2; }", "RBF") == "no error");
    CHECK_THAT
    (
        errorOf("rigidLayers { patches (walls); innerDistance 0.2; outerDistance 0.2; }"),
        Contains("outerDistance 0.2 must be larger than innerDistance 0.2")
    );
    CHECK_THAT
    (
        errorOf("rigidLayers { patches (walls); innerDistance -0.1; outerDistance 0.2; }"),
        Contains("innerDistance")
    );
    CHECK_THAT
    (
        errorOf("rigidLayers { patches (walls); innerDistance 0.1; }", "RBF"),
        Contains("outerDistance")
    );
    CHECK_THAT(errorOf("rigidLayers (walls);"), Contains("rigidLayers must be a dictionary { patches (...);"));
    CHECK(errorOf("rigidLayers { patches (\"w.*\"); innerDistance 0; outerDistance 0.2; }") == "no error");
}
