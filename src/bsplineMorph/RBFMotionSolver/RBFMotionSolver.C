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
    }
}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::RBFMotionSolver::readCoeffs()
{
    const dictionary& dict = coeffDict();
    params_.function =
        kernelNames.lookupOrDefault("function", dict, rbf::kernel::inverseMultiquadric);
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
    if (params_.function == rbf::kernel::thinPlateSpline && !params_.polynomial)
    {
        FatalIOErrorInFunction(dict)
            << "function thinPlateSpline needs polynomial true" << exit(FatalIOError);
    }
}


template<int D>
std::string Foam::RBFMotionSolver::interpolateD
(
    std::vector<std::unique_ptr<rbf::interpolant<D>>>& rbf,
    std::vector<double>& result
)
{
    const boundaryConstraints& bc = constraints();
    const labelList& points = evalPoints();
    const mba::pointsView<D> eval(evalCoordinates(), std::size_t(points.size()));
    std::vector<double> values, out;
    result.resize(D*points.size());
    label size = 0;
    scalar rcond = GREAT;
    try
    {
        for (label k = 0; k < D; ++k)
        {
            values.clear();
            for (const label i : selected_[slot()][k]) values.push_back(bc.values()[i*D + k]);
            rbf[k]->fit(values);
            rbf[k]->evaluate(eval, out);
            forAll(points, i)
            {
                result[i*D + k] = out[i];
            }
            size = max(size, label(rbf[k]->stats().size));
            rcond = min(rcond, rbf[k]->stats().rcond);
        }
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction << "RBF interpolation failed: " << e.what() << exit(FatalError);
    }
    OStringStream os;
    os  << D << " systems of size up to " << size
        << ", reciprocal condition " << rcond;
    return os.str();
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

void Foam::RBFMotionSolver::buildPlan()
{
    const boundaryConstraints& bc = constraints();
    const labelList& dirs = bc.directions();
    const label D = dirs.size();
    const pointField& p0 = points0();
    const clockTime timer;

    selected_[slot()].assign(D, {});
    controlXyz_[slot()].assign(D, {});
    forAll(bc.controlPoints(), i)
    {
        for (label k = 0; k < D; ++k)
        {
            if (!bc.mask()[i*D + k]) continue;
            selected_[slot()][k].push_back(i);
            for (const label d : dirs)
            {
                controlXyz_[slot()][k].push_back(p0[bc.controlPoints()[i]][d]);
            }
        }
    }
    rbf3_[slot()].clear();
    rbf2_[slot()].clear();
    try
    {
        for (label k = 0; k < D; ++k)
        {
            const std::size_t n = selected_[slot()][k].size();
            if (D == 3)
            {
                rbf3_[slot()].emplace_back(new rbf::interpolant<3>
                    (comm_, params_, 1, mba::pointsView<3>(controlXyz_[slot()][k].data(), n)));
            }
            else
            {
                rbf2_[slot()].emplace_back(new rbf::interpolant<2>
                    (comm_, params_, 1, mba::pointsView<2>(controlXyz_[slot()][k].data(), n)));
            }
        }
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "Cannot set up the RBF systems: " << e.what() << exit(FatalError);
    }
    Info<< type() << ": " << kernelNames[params_.function] << " systems for "
        << bc.nControlGlobal() << " control points factored in "
        << timer.elapsedTime() << " s" << endl;
}


std::string Foam::RBFMotionSolver::interpolate(std::vector<double>& values)
{
    if (!rbf3_[slot()].empty())
    {
        return interpolateD(rbf3_[slot()], values);
    }
    return interpolateD(rbf2_[slot()], values);
}


// ************************************************************************* //
