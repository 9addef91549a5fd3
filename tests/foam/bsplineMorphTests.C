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
#include "IStringStream.H"
#include "IOdictionary.H"

#include <limits>

using namespace Foam;

namespace
{
    autoPtr<motionSolver> bsplineSolver(const std::string& coeffs)
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
            dictionary
            (
                IStringStream
                (
                    "motionSolver multilevelBSpline; multilevelBSplineCoeffs {" + coeffs + "}"
                )()
            )
        );
        return motionSolver::New(bsmTest::mesh(), dict);
    }

    std::string errorOf(const std::string& coeffs)
    {
        try
        {
            bsplineSolver(coeffs);
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
    // every wall point is fixed at zero: the mesh does not move
    solver->solve();
    const pointField p1(solver->curPoints());
    const pointField& p0 = bsmTest::mesh().points();
    forAll(p0, pointi)
    {
        REQUIRE(mag(p1[pointi] - p0[pointi]) == 0);
    }
}


TEST_CASE("multilevelBSpline: invalid keyword values name the entry", "[foam][bsplineMorph][errors]")
{
    using Catch::Matchers::Contains;
    CHECK_THAT(errorOf("tolerance -1;"), Contains("tolerance"));
    CHECK_THAT(errorOf("maxLevels 0;"), Contains("maxLevels"));
    CHECK_THAT(errorOf("maxLevels 31;"), Contains("maxLevels"));
    CHECK_THAT(errorOf("initialGrid 0;"), Contains("initialGrid"));
    CHECK_THAT(errorOf("bucketTiles 0;"), Contains("bucketTiles"));
    const std::string approx = errorOf("initialApproximation quadratic;");
    CHECK_THAT(approx, Contains("quadratic") && Contains("affine") && Contains("none"));
    const std::string inverted = errorOf("invertedCells maybe;");
    CHECK_THAT(inverted, Contains("maybe") && Contains("fatal") && Contains("warn"));
    CHECK_THAT(errorOf("relativeTolerance perhaps;"), Contains("perhaps"));
    CHECK(errorOf("tolerance 1e-8; maxLevels 8; initialGrid 2; initialApproximation none;") == "no error");
}


TEST_CASE("multilevelBSpline: a NaN displacement stops before the mesh moves", "[foam][bsplineMorph][errors]")
{
    autoPtr<motionSolver> solver = bsplineSolver("");
    displacementMotionSolver& dms = refCast<displacementMotionSolver>(solver.ref());
    const label patchi = bsmTest::mesh().boundaryMesh().findPatchID("walls");
    REQUIRE(patchi >= 0);
    pointPatchVectorField& pf = dms.pointDisplacement().boundaryFieldRef()[patchi];
    vectorField bad(pf.size(), vector(0.1, 0, 0));
    if (bad.size())
    {
        bad[0].x() = std::numeric_limits<scalar>::quiet_NaN();
    }
    pf == bad;
    try
    {
        solver->solve();
        FAIL("no error raised");
    }
    catch (const Foam::error& err)
    {
        CHECK_THAT(std::string(err.message()), Catch::Matchers::Contains("non-finite") && Catch::Matchers::Contains("walls"));
    }
}
