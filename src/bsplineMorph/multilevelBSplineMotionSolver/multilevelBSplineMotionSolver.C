/*---------------------------------------------------------------------------*\
  =========                 |
  \\      /  F ield         | bsplineMorph: multilevel B-spline mesh morphing
   \\    /   O peration     |
    \\  /    A nd           | Copyright (C) 2026 bsplineMorph developers
     \\/     M anipulation  |
-------------------------------------------------------------------------------
License
    This file is part of bsplineMorph, built on OpenFOAM.

    bsplineMorph is free software: you can redistribute it and/or modify it
    under the terms of the GNU General Public License as published by the
    Free Software Foundation, either version 3 of the License, or (at your
    option) any later version. See <http://www.gnu.org/licenses/>.

\*---------------------------------------------------------------------------*/

#include "multilevelBSplineMotionSolver.H"
#include "coeffsInput.H"
#include "addToRunTimeSelectionTable.H"
#include "OStringStream.H"
#include "Enum.H"
#include "clockTime.H"

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

namespace Foam
{
    defineTypeNameAndDebug(multilevelBSplineMotionSolver, 0);

    addToRunTimeSelectionTable
    (
        motionSolver,
        multilevelBSplineMotionSolver,
        dictionary
    );

    addToRunTimeSelectionTable
    (
        displacementMotionSolver,
        multilevelBSplineMotionSolver,
        displacement
    );

    namespace
    {
        enum class initialApproximation { affine, none };
        const Enum<initialApproximation> initialApproximationNames
        ({
            { initialApproximation::affine, "affine" },
            { initialApproximation::none, "none" },
        });

    }
}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::multilevelBSplineMotionSolver::readCoeffs()
{
    const dictionary& dict = coeffDict();

    params_.tolerance = coeffsInput::getInRange<scalar>(dict, "tolerance", 1e-6, 0);
    params_.relative = dict.lookupOrDefault<bool>("relativeTolerance", true);
    params_.maxLevels = coeffsInput::getInRange<label>(dict, "maxLevels", 12, 1, 30);
    params_.initialGrid =
        coeffsInput::getInRange<label>(dict, "initialGrid", 1, 1, 1 << 20);
    params_.affine =
        initialApproximationNames.lookupOrDefault
        (
            "initialApproximation", dict, initialApproximation::affine
        ) == initialApproximation::affine;
    params_.bucketTiles = coeffsInput::getInRange<label>(dict, "bucketTiles", 32, 1);
    warnUnknownKeywords
    ({
        "tolerance", "relativeTolerance", "maxLevels", "initialGrid",
        "initialApproximation", "bucketTiles"
    });
}


void Foam::multilevelBSplineMotionSolver::buildPlan()
{
    const boundaryConstraints& bc = constraints();
    std::vector<double>& controlXyz = controlXyz_[slot()];
    std::unique_ptr<mba::multilevel<3>>& plan3 = plan3_[slot()];
    std::unique_ptr<mba::multilevel<2>>& plan2 = plan2_[slot()];
    const labelList& dirs = bc.directions();
    const label D = dirs.size();
    const pointField& p0 = points0();

    controlXyz.clear();
    for (const label pointi : bc.controlPoints())
    {
        for (const label d : dirs) controlXyz.push_back(p0[pointi][d]);
    }
    plan3.reset();
    plan2.reset();
    try
    {
        const std::size_t nEval = evalPoints().size();
        if (D == 3)
        {
            plan3.reset
            (
                new mba::multilevel<3>
                (
                    comm_, params_, 3,
                    mba::pointsView<3>(controlXyz.data(), bc.controlPoints().size()),
                    bc.mask(), mba::pointsView<3>(evalCoordinates(), nEval)
                )
            );
        }
        else if (D == 2)
        {
            plan2.reset
            (
                new mba::multilevel<2>
                (
                    comm_, params_, 2,
                    mba::pointsView<2>(controlXyz.data(), bc.controlPoints().size()),
                    bc.mask(), mba::pointsView<2>(evalCoordinates(), nEval)
                )
            );
        }
        else
        {
            FatalErrorInFunction
                << "Meshes with " << D << " solution directions are not supported"
                << " (2D or 3D only)" << exit(FatalError);
        }
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "Cannot set up the multilevel B-spline plan: " << e.what()
            << exit(FatalError);
    }
    Info<< type() << ": " << (slot() ? "re-fit " : "") << "plan for "
        << bc.nControlGlobal() << " control points, "
        << returnReduce(p0.size(), sumOp<label>()) << " mesh points ("
        << returnReduce(evalPoints().size(), sumOp<label>()) << " interpolated), " << D << "D"
        << endl;
}


template<int D>
std::string Foam::multilevelBSplineMotionSolver::morph
(
    mba::multilevel<D>& plan,
    std::vector<double>& values
)
{
    scalar evalSeconds = 0;
    try
    {
        plan.fit(constraints().values());
        const clockTime timer;
        plan.evaluate(values);
        evalSeconds = timer.elapsedTime();
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "Multilevel B-spline fit failed: " << e.what() << exit(FatalError);
    }

    const mba::fitReport& r = plan.report();
    double nodes = 0, bytes = 0, messages = 0;
    label separated = 0;
    for (const mba::levelStats& s : plan.stats())
    {
        if (s.level < r.levels)
        {
            separated += s.separated;
            nodes += s.nodes;
            bytes += s.bytesReceivedPerApply;
            messages += s.messagesReceived;
            if (debug)
            {
                Pout<< type() << ": level " << s.level << " h " << s.h << " nodes " << s.nodes
                    << " tiles own/view " << s.ownTiles << '/' << s.viewTiles
                    << (s.dense ? " dense" : " sparse") << (s.separated ? " separated" : "")
                    << " received " << s.bytesReceivedPerApply
                    << " B, max residual " << s.maxResidual << ", " << s.seconds << " s (plan "
                    << s.planSeconds << " s)" << endl;
            }
        }
    }
    nodes = returnReduce(nodes, sumOp<scalar>());
    const scalar bytesMax = returnReduce(bytes, maxOp<scalar>());
    bytes = returnReduce(bytes, sumOp<scalar>());
    const scalar messagesMax = returnReduce(messages, maxOp<scalar>());
    messages = returnReduce(messages, sumOp<scalar>());
    const scalar planMB = returnReduce(scalar(plan.bytes()), sumOp<scalar>())/1048576;
    OStringStream os;
    os  << r.levels << " levels (" << separated << " separated), max residual " << r.maxResidual
        << " (threshold " << r.threshold << (r.converged ? "" : ", not reached")
        << "), " << label(nodes) << " lattice nodes, plan " << planMB << " MB, "
        << label(bytes) << " bytes exchanged (" << label(bytesMax) << " by one rank) in "
        << label(messages) << " messages (" << label(messagesMax) << " by one rank), fit "
        << r.seconds << " s, evaluation " << evalSeconds << " s";
    return os.str();
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::multilevelBSplineMotionSolver::multilevelBSplineMotionSolver
(
    const polyMesh& mesh,
    const IOdictionary& dict
)
:
    interpolatingMotionSolver(mesh, dict, typeName)
{
    readCoeffs();
}


Foam::multilevelBSplineMotionSolver::multilevelBSplineMotionSolver
(
    const polyMesh& mesh,
    const IOdictionary& dict,
    const pointVectorField& pointDisplacement,
    const pointIOField& points0
)
:
    interpolatingMotionSolver(mesh, dict, pointDisplacement, points0, typeName)
{
    readCoeffs();
}


// * * * * * * * * * * * * * * * * Destructor  * * * * * * * * * * * * * * * //

Foam::multilevelBSplineMotionSolver::~multilevelBSplineMotionSolver()
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

std::string Foam::multilevelBSplineMotionSolver::interpolate
(
    std::vector<double>& values
)
{
    if (plan3_[slot()])
    {
        return morph(*plan3_[slot()], values);
    }
    return morph(*plan2_[slot()], values);
}


// ************************************************************************* //
