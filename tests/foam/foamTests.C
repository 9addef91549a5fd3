/*---------------------------------------------------------------------------*\
    bsplineMorph: the first OpenFOAM-side tests: the behaviour of Debian's
    OpenFOAM v1912 that the project depends on.
\*---------------------------------------------------------------------------*/

#include <catch2/catch.hpp>

#include "foamTestCase.H"
#include "IStringStream.H"
#include "IOdictionary.H"
#include "motionSolver.H"
#include "syncTools.H"

using namespace Foam;

namespace
{
    autoPtr<motionSolver> solverFromString(const std::string& text)
    {
        IOdictionary dict
        (
            IOobject
            (
                "dynamicMeshDict",
                bsmTest::mesh().time().constant(),
                bsmTest::mesh(),
                IOobject::NO_READ,
                IOobject::NO_WRITE,
                false
            ),
            dictionary(IStringStream(text)())
        );
        return motionSolver::New(bsmTest::mesh(), dict);
    }
}


TEST_CASE("the harness case loads with the cells blockMesh made", "[foam]")
{
    const fvMesh& mesh = bsmTest::mesh();
    const int* n = bsmTest::caseCells;
    CHECK(returnReduce(mesh.nCells(), sumOp<label>()) == n[0]*n[1]*n[2]);
    // Points shared by processors counted once: owned by the lowest rank
    labelList owner(mesh.nPoints(), Pstream::myProcNo());
    syncTools::syncPointList(mesh, owner, minEqOp<label>(), labelMax);
    label owned = 0;
    forAll(owner, pointi) owned += owner[pointi] == Pstream::myProcNo();
    CHECK(returnReduce(owned, sumOp<label>()) == (n[0] + 1)*(n[1] + 1)*(n[2] + 1));
    CHECK(mesh.boundaryMesh().findPatchID("walls") >= 0);
    if (Pstream::parRun())
    {
        CHECK(mesh.nCells() < n[0]*n[1]*n[2]);
        CHECK(mesh.nCells() > 0);
    }
    // Unit box: the bounding box over all ranks
    const boundBox bb(mesh.points(), true);
    CHECK_THAT(bb.min().x(), Catch::WithinAbs(0.0, 1e-15));
    CHECK_THAT(bb.max().x(), Catch::WithinAbs(1.0, 1e-15));
}


TEST_CASE("a motion solver is selected from a dictionary and moves points", "[foam]")
{
    autoPtr<motionSolver> solver = solverFromString
    (
        "motionSolver solidBody;"
        "solidBodyMotionFunction linearMotion;"
        "linearMotionCoeffs { velocity (0.2 -0.1 0.05); }"
    );
    REQUIRE(solver.valid());
    CHECK(solver->type() == "solidBody");

    Time& runTime = bsmTest::runTime();
    const scalar t0 = runTime.value();
    runTime.setTime(0.5, 1);
    const tmp<pointField> tnewPoints = solver->newPoints();
    runTime.setTime(t0, 0);

    const pointField& p0 = bsmTest::mesh().points();
    const pointField& p1 = tnewPoints();
    REQUIRE(p1.size() == p0.size());
    const vector d(0.1, -0.05, 0.025);
    forAll(p0, pointi)
    {
        for (direction c = 0; c < 3; ++c)
        {
            REQUIRE_THAT(p1[pointi][c] - p0[pointi][c], Catch::WithinAbs(d[c], 1e-14));
        }
    }
}


TEST_CASE("an unknown motion solver is a fatal error naming the valid ones", "[foam]")
{
    try
    {
        solverFromString("motionSolver noSuchSolver;");
        FAIL("no error raised");
    }
    catch (const Foam::error& err)
    {
        const std::string msg(err.message());
        CHECK(msg.find("noSuchSolver") != std::string::npos);
        CHECK(msg.find("solidBody") != std::string::npos);
    }
}


TEST_CASE("a dictionary with a syntax error is rejected", "[foam]")
{
    REQUIRE_THROWS(solverFromString("motionSolver solidBody; solidBodyMotionFunction ;"));
}
