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

#include "RBFMotionSolver.H"
#include "coeffsInput.H"
#include "addToRunTimeSelectionTable.H"
#include "OStringStream.H"
#include "Enum.H"
#include "clockTime.H"

#include <utility>

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

namespace Foam
{
    defineTypeNameAndDebug(RBFMotionSolver, 0);
    addToRunTimeSelectionTable(motionSolver, RBFMotionSolver, dictionary);
    addToRunTimeSelectionTable
    (
        displacementMotionSolver,
        RBFMotionSolver,
        displacement
    );

    namespace
    {
        const Enum<rbf::kernel> kernelNames
        ({
            { rbf::kernel::inverseMultiquadric, "inverseMultiquadric" },
            { rbf::kernel::thinPlateSpline, "thinPlateSpline" },
            { rbf::kernel::wendlandC2, "wendlandC2" },
        });

        //- RBF interpolants in D dimensions, one per solution direction,
        //  each centred on the control points that constrain that direction
        template<int D>
        class rbfInterpolator
        :
            public boundaryInterpolator
        {
            //- Per direction: indices into the control points, and their
            //  coordinates (which the interpolant views)
            std::vector<std::vector<label>> selected_;
            std::vector<std::vector<double>> controlXyz_;

            //- Per direction: the interpolant
            std::vector<std::unique_ptr<rbf::interpolant<D>>> rbf_;

            //- The evaluation points
            const mba::pointsView<D> eval_;

        public:

            rbfInterpolator
            (
                const mba::communicator& comm,
                const rbf::params& params,
                const boundaryConstraints& bc,
                const pointField& points0,
                const double* evalXyz,
                const std::size_t nEval
            );

            //- Fit each direction's values, evaluate at the evaluation
            //  points
            virtual interpolationReport interpolate
            (
                const boundaryConstraints& bc,
                std::vector<double>& result
            );
        };
    }
}


// * * * * * * * * * * * * * Local Member Functions  * * * * * * * * * * * * //

template<int D>
Foam::rbfInterpolator<D>::rbfInterpolator
(
    const mba::communicator& comm,
    const rbf::params& params,
    const boundaryConstraints& bc,
    const pointField& points0,
    const double* evalXyz,
    const std::size_t nEval
)
:
    selected_(D),
    controlXyz_(D),
    eval_(evalXyz, nEval)
{
    forAll(bc.controlPoints(), i)
    {
        for (label k = 0; k < D; ++k)
        {
            if (!bc.mask()[i*D + k]) continue;
            selected_[k].push_back(i);
            bc.frame().appendCoordinates
            (
                points0[bc.controlPoints()[i]], controlXyz_[k]
            );
        }
    }
    for (label k = 0; k < D; ++k)
    {
        const std::size_t n = selected_[k].size();
        rbf_.emplace_back(new rbf::interpolant<D>
            (comm, params, 1, mba::pointsView<D>(controlXyz_[k].data(), n)));
    }
}


template<int D>
Foam::interpolationReport Foam::rbfInterpolator<D>::interpolate
(
    const boundaryConstraints& bc,
    std::vector<double>& result
)
{
    const std::size_t nEval = eval_.size;
    std::vector<double> values, out;
    result.resize(D*nEval);
    label size = 0;
    scalar rcond = GREAT;
    try
    {
        for (label k = 0; k < D; ++k)
        {
            values.clear();
            for (const label i : selected_[k]) values.push_back(bc.values()[i*D + k]);
            rbf_[k]->fit(values);
            rbf_[k]->evaluate(eval_, out);
            for (std::size_t i = 0; i < nEval; ++i)
            {
                result[i*D + k] = out[i];
            }
            size = max(size, label(rbf_[k]->stats().size));
            rcond = min(rcond, rbf_[k]->stats().rcond);
        }
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction << "RBF interpolation failed: " << e.what() << exit(FatalError);
    }
    OStringStream os;
    os  << D << " systems of size up to " << size
        << ", reciprocal condition " << rcond;
    interpolationReport report;
    report.summary = os.str();
    report.add("systems", D);
    report.add("largestSystem", size);
    report.add("reciprocalCondition", rcond);
    return report;
}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::RBFMotionSolver::readCoeffs()
{
    const dictionary& dict = coeffDict();
    params_.function =
        coeffsInput::getEnum(dict, "function", kernelNames, rbf::kernel::thinPlateSpline);
    params_.shapeParameter =
        coeffsInput::getInRange<scalar>(dict, "shapeParameter", 0.05, SMALL);
    params_.supportRadius =
        coeffsInput::getInRange<scalar>(dict, "supportRadius", 0.5, SMALL);
    params_.polynomial = dict.lookupOrDefault<bool>("polynomial", true);
    params_.maxPoints = coeffsInput::getInRange<label>(dict, "maxPoints", 20000, 1);
    params_.greedyTolerance =
        coeffsInput::getInRange<scalar>(dict, "greedyTolerance", 0, 0);
    params_.greedyBatch = coeffsInput::getInRange<label>(dict, "greedyBatch", 50, 1);
    warnUnknownKeywords
    ({
        "function", "shapeParameter", "supportRadius", "polynomial",
        "maxPoints", "greedyTolerance", "greedyBatch"
    });
    // (each parameter belongs to one function: given to another, a warning)
    const std::pair<word, rbf::kernel> owners[] =
    {
        {"shapeParameter", rbf::kernel::inverseMultiquadric},
        {"supportRadius", rbf::kernel::wendlandC2}
    };
    for (const auto& own : owners)
    {
        coeffsInput::warnUnread
        (
            dict, own.first, "function", kernelNames[own.second],
            kernelNames[params_.function]
        );
    }
    if (params_.function == rbf::kernel::thinPlateSpline && !params_.polynomial)
    {
        FatalIOErrorInFunction(dict)
            << "function thinPlateSpline needs polynomial true" << exit(FatalIOError);
    }
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::RBFMotionSolver::RBFMotionSolver
(
    const polyMesh& mesh,
    const IOdictionary& dict
)
:
    interpolatingMotionSolver(mesh, dict, typeName)
{
    readCoeffs();
}


Foam::RBFMotionSolver::RBFMotionSolver
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

Foam::RBFMotionSolver::~RBFMotionSolver()
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

std::unique_ptr<Foam::boundaryInterpolator>
Foam::RBFMotionSolver::newInterpolator
(
    const boundaryConstraints& bc,
    const bool refit
)
{
    const label D = bc.frame().size();
    const std::size_t nEval = evalPoints().size();
    const clockTime timer;
    std::unique_ptr<boundaryInterpolator> interpolator;
    try
    {
        if (D == 3)
        {
            interpolator.reset(new rbfInterpolator<3>
                (comm_, params_, bc, base(), evalCoordinates(), nEval));
        }
        else
        {
            interpolator.reset(new rbfInterpolator<2>
                (comm_, params_, bc, base(), evalCoordinates(), nEval));
        }
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "Cannot set up the RBF systems: " << e.what()
            << (
                   params_.function == rbf::kernel::thinPlateSpline
                 ? ""
                 : ". The default function thinPlateSpline has no shape"
                   " parameter and solved on every case measured (README,"
                   " The RBF baseline); or lower shapeParameter /"
                   " supportRadius"
               )
            << exit(FatalError);
    }
    Info<< type() << ": " << kernelNames[params_.function] << " systems for "
        << bc.nControlGlobal() << " control points factored in "
        << timer.elapsedTime() << " s" << endl;
    return interpolator;
}


// ************************************************************************* //
