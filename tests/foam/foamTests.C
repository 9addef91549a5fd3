/*---------------------------------------------------------------------------*\
    bsplineMorph: the test harness itself: the case the OpenFOAM-side tests
    run on (tests/foam/makeCase) is the one they assume, serial and
    decomposed.
\*---------------------------------------------------------------------------*/

#include <catch2/catch.hpp>

#include "foamTestCase.H"
#include "syncTools.H"

using namespace Foam;

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
