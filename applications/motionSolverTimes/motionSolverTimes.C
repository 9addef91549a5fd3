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

Application
    motionSolverTimes

Group
    grpMeshManipulationUtilities

Description
    Times the motion solver of constant/dynamicMeshDict step by step: the
    wall time of each motionSolver::newPoints() (the solve: boundary
    conditions, interpolation or equation, the new points), and nothing else
    (the mesh is moved between steps and its points written at the
    controlDict's write times, outside the timings, but not checked). A fair per-step comparison
    of any motion solvers, displacementLaplacian included, which logs no
    time of its own (benchmarks/run).

    Prints one line per step: "motionSolverTimes: step <time> <solve> s, mesh
    update <seconds> s" (the mesh update, fvMesh::movePoints, includes what
    the solver's mesh objects redo for moved points).

Usage
    motionSolverTimes [-parallel]

\*---------------------------------------------------------------------------*/

#include "fvCFD.H"
#include "motionSolver.H"
#include "clockTime.H"
#include "pointIOField.H"

using namespace Foam;

int main(int argc, char* argv[])
{
    argList::addNote
    (
        "Wall time of each step of the motion solver of"
        " constant/dynamicMeshDict (motionSolver::newPoints), nothing else"
    );
    #include "setRootCase.H"
    #include "createTime.H"
    #include "createMesh.H"

    const IOdictionary dict
    (
        IOobject
        (
            "dynamicMeshDict",
            runTime.constant(),
            mesh,
            IOobject::MUST_READ,
            IOobject::NO_WRITE,
            false
        )
    );
    autoPtr<motionSolver> solver = motionSolver::New(mesh, dict);

    while (runTime.run())
    {
        ++runTime;
        const clockTime timer;
        // the new points as dynamicMotionSolverFvMesh takes them: the tmp
        // itself (copying it into a field would time a copy that a solver
        // handing out its own points pays and one returning a new field not)
        const tmp<pointField> tp(solver->newPoints());
        const pointField& p = tp();
        const scalar solve = returnReduce(timer.elapsedTime(), maxOp<scalar>());
        const clockTime timer2;
        mesh.movePoints(p);
        const scalar move = returnReduce(timer2.elapsedTime(), maxOp<scalar>());
        Info<< "motionSolverTimes: step " << runTime.timeName() << ' ' << solve << " s, mesh update "
            << move << " s" << endl;
        if (runTime.writeTime())
        {
            // the moved points (the mesh itself is not a dynamic one that
            // would write them)
            pointIOField
            (
                IOobject
                (
                    "points",
                    runTime.timeName(),
                    polyMesh::meshSubDir,
                    mesh,
                    IOobject::NO_READ,
                    IOobject::NO_WRITE,
                    false
                ),
                mesh.points()
            ).write();
        }
        runTime.write();
    }

    Info<< "End" << endl;
    return 0;
}


// ************************************************************************* //
