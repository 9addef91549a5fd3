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

#include "boundaryConstraints.H"
#include "sharedPoints.H"
#include "solutionFrame.H"
#include "OStringStream.H"
#include "IStringStream.H"

// The patches whose conditions project their points onto surfaces
// (surfaceSlipDisplacement): which they are, and their points on every rank
// alike

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    //- Whether a condition (as it writes itself) projects onto one smooth
    //  surface: a sphere, cylinder or plane by its type as written in full
    //  or short (several surfaces meet in edges)
    bool oneSmoothSurface(const Foam::dictionary& written)
    {
        using namespace Foam;
        static const wordHashSet smoothTypes
        {
            "searchableSphere", "sphere", "searchableCylinder", "cylinder",
            "searchablePlane", "plane"
        };
        const dictionary* geometry = written.findDict("geometry");
        return
            geometry && geometry->size() == 1 && geometry->first()->isDict()
         && smoothTypes.found
            (
                geometry->first()->dict().lookupOrDefault<word>("type", word::null)
            );
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::boundaryConstraints::findProjectingPatches
(
    const pointVectorField& pointDisplacement
)
{
    const polyMesh& mesh = pMesh_();
    // The points that conditions project onto surfaces
    labelList onSurface(mesh.nPoints(), 0);
    DynamicList<label> projecting, smooth;
    for (const pointPatchVectorField& pf : pointDisplacement.boundaryField())
    {
        if (projectsOntoSurface(pf))
        {
            // (its projectMode as it writes it: the class keeps it private)
            OStringStream os;
            pf.write(os);
            const dictionary written((IStringStream(os.str()))());
            if (written.lookupOrDefault<word>("projectMode", word::null) == "pointNormal")
            {
                FatalErrorInFunction
                    << pointDisplacement.objectPath() << ", boundaryField "
                    << pf.patch().name() << ": " << pf.type() << " with"
                    << " projectMode pointNormal projects along point normals,"
                    << " which a rank forms from its own faces only: the points"
                    << " would differ between decompositions. Use projectMode"
                    << " nearest or fixedNormal. The mesh is not moved"
                    << exit(FatalError);
            }
            projecting.append(pf.patch().index());
            UIndirectList<label>(onSurface, pf.patch().meshPoints()) = 1;
            if (oneSmoothSurface(written))
            {
                smooth.append(pf.patch().index());
            }
        }
    }
    projectingPatches_.transfer(projecting);
    smoothProjectingPatches_.transfer(smooth);
    surfaceConditionPoints_ = onAnyRank(mesh, onSurface);
    onSurface_.resize(mesh.nPoints());
    onSurface_.set(surfaceConditionPoints_);
    projectedByCondition_ = onSurface_;
    nSurfaceGlobal_ = returnReduce(surfaceConditionPoints_.size(), sumOp<label>());
    if (Pstream::parRun())
    {
        // Per projecting patch: its points on any rank, their copies through
        // processor patches, and those this rank's faces of it hold
        surfacePoints_.setSize(projectingPatches_.size());
        projectsHere_.setSize(projectingPatches_.size());
        surfaceSync_.resize(projectingPatches_.size());
        forAll(projectingPatches_, k)
        {
            const labelList& meshPoints = mesh.boundaryMesh()[projectingPatches_[k]].meshPoints();
            projectsHere_[k].resize(mesh.nPoints());
            projectsHere_[k].set(meshPoints);
            labelList flag(mesh.nPoints(), 0);
            UIndirectList<label>(flag, meshPoints) = 1;
            surfacePoints_[k] = onAnyRank(mesh, flag);
            surfaceSync_[k] = std::make_shared<const sharedPoints>(mesh, surfacePoints_[k], true);
        }
    }
}


void Foam::boundaryConstraints::syncProjected
(
    const label k,
    vectorField& displacement
) const
{
    // A rank that holds a point of the projecting patch but none of the
    // patch's faces about it (a point of a floor beside a projected
    // cylinder) did not project it: it takes the projection of a rank that
    // did (the point's owner's, else the first rank in order that did; all
    // that did computed the same, from the values the patches before this
    // one left, which these syncs keep the same on every rank)
    if (surfaceSync_.empty())
    {
        return;
    }
    const vector none(vector::max);
    const bitSet& here = projectsHere_[k];
    surfaceWork_.setSize(displacement.size());
    for (const label pointi : surfacePoints_[k])
    {
        surfaceWork_[pointi] = here.test(pointi) ? displacement[pointi] : none;
    }
    surfaceSync_[k]->combineMesh
    (
        surfaceWork_,
        [&none](vector& x, const vector& y) { if (x == none) x = y; },
        none
    );
    for (const label pointi : surfacePoints_[k])
    {
        if (!here.test(pointi) && surfaceWork_[pointi] != none)
        {
            displacement[pointi] = surfaceWork_[pointi];
        }
    }
}


void Foam::boundaryConstraints::slideBeforeProjection(vectorField& displacement) const
{
    // (the fit meets its control points to its tolerance only: a point of
    // a projected wall that also lies on a symmetry or slip plane would keep
    // the fit's error across that plane, which the projection onto the
    // surface does not remove)
    const solutionFrame& frame = *frame_;
    for (const label pointi : surfaceConditionPoints_)
    {
        if (!fixed_[pointi] && slide_[pointi].first() > 0)
        {
            slideOne(frame, pointi, displacement[pointi]);
        }
    }
}


// ************************************************************************* //
