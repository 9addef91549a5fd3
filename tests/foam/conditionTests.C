/*---------------------------------------------------------------------------*\
    bsplineMorph: the solvers update each boundary condition once a step,
    and move the mesh with the values it then holds: a condition with a
    state (sixDoFRigidBodyDisplacement's body, say) advances it once.
\*---------------------------------------------------------------------------*/

#include <catch2/catch.hpp>

#include "foamTestCase.H"
#include "displacementMotionSolver.H"
#include "fixedValuePointPatchFields.H"

using namespace Foam;

namespace
{
    //- A fixed value that moves by (0.01 0 0) at each update: its updates
    //  counted, as a condition with a state advances it
    class countingDisplacement
    :
        public fixedValuePointPatchVectorField
    {
    public:

        static label nUpdates;

        //- The precision of Info's stream at the last update (a condition
        //  that logs its state, as sixDoFRigidBodyDisplacement does, logs it
        //  at the case's precision, not the solver's log lines')
        static label precision;

        countingDisplacement(const fixedValuePointPatchVectorField& pf)
        :
            fixedValuePointPatchVectorField(pf)
        {}

        countingDisplacement(const countingDisplacement& pf, const DimensionedField<vector, pointMesh>& iF)
        :
            fixedValuePointPatchVectorField(pf, iF)
        {}

        autoPtr<pointPatchVectorField> clone() const
        {
            return autoPtr<pointPatchVectorField>(new countingDisplacement(*this));
        }

        autoPtr<pointPatchVectorField> clone(const DimensionedField<vector, pointMesh>& iF) const
        {
            return autoPtr<pointPatchVectorField>(new countingDisplacement(*this, iF));
        }

        void updateCoeffs()
        {
            if (updated())
            {
                return;
            }
            ++nUpdates;
            precision = Sout.precision();
            vectorField::operator=(vector(0.01*nUpdates, 0, 0));
            fixedValuePointPatchVectorField::updateCoeffs();
        }
    };

    label countingDisplacement::nUpdates = 0;
    label countingDisplacement::precision = 0;
}


TEST_CASE("Each condition is updated once a step, the mesh moved with its values, at the case's log precision", "[foam][bsplineMorph][rbf]")
{
    // (and with rebase on, whose step checks the strain first; the walls at
    // 0.01 a step against the box's size 1 rebase on no step here)
    const std::string type = GENERATE(as<std::string>(), "multilevelBSpline", "RBF");
    const std::string coeffs = GENERATE(as<std::string>(), "", "rebase on;");
    autoPtr<motionSolver> solver = bsmTest::solverOf(type, coeffs);
    displacementMotionSolver& dms = refCast<displacementMotionSolver>(solver.ref());
    const label patchi = bsmTest::mesh().boundaryMesh().findPatchID("walls");
    REQUIRE(patchi >= 0);
    pointVectorField& pd = dms.pointDisplacement();
    pd.boundaryFieldRef().set
    (
        patchi,
        new countingDisplacement
        (
            fixedValuePointPatchVectorField(pd.boundaryField()[patchi].patch(), pd())
        )
    );
    countingDisplacement::nUpdates = 0;
    const int casePrecision = Sout.precision(13);
    const labelList& meshPoints = pd.boundaryField()[patchi].patch().meshPoints();
    for (label step = 1; step <= 3; ++step)
    {
        solver->solve();
        INFO(type << " {" << coeffs << "}, step " << step);
        CHECK(countingDisplacement::nUpdates == step);
        CHECK(countingDisplacement::precision == 13);
        // the walls' points where the condition now says (its own values,
        // and pointDisplacement's at its points)
        const vectorField& own = refCast<const countingDisplacement>(pd.boundaryField()[patchi]);
        const vectorField held(pd.boundaryField()[patchi].patchInternalField());
        const pointField p1(solver->curPoints());
        scalar worst = 0;
        forAll(meshPoints, i)
        {
            const label pointi = meshPoints[i];
            worst = max(worst, mag(p1[pointi] - dms.points0()[pointi] - vector(0.01*step, 0, 0)));
            worst = max(worst, mag(held[i] - vector(0.01*step, 0, 0)));
            worst = max(worst, mag(own[i] - vector(0.01*step, 0, 0)));
        }
        CHECK(returnReduce(worst, maxOp<scalar>()) <= 1e-15);
    }
    Sout.precision(casePrecision);
}
