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
#include "globalMeshData.H"
#include "polyMesh.H"
#include "emptyPolyPatch.H"
#include "coupledPolyPatch.H"
#include "PstreamBuffers.H"
#include "OStringStream.H"

#include <algorithm>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    // Lexicographic order of points (copies of a point are equal bit for bit)
    bool before(const Foam::point& a, const Foam::point& b)
    {
        return
            a.x() < b.x()
         || (a.x() == b.x() && (a.y() < b.y() || (a.y() == b.y() && a.z() < b.z())));
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::boundaryConstraints::warnSplitBaffles
(
    const polyMesh& mesh,
    const pointField& points0
)
{
    if (!Pstream::parRun())
    {
        return;
    }
    // This rank's points of patches that are not couplings (nor empty: a
    // cyclicAMI's sides are separate points however decomposed), with the
    // first such patch that holds them, but those on coupled patches
    // (joined to their copies on other ranks)
    const polyBoundaryMesh& pbm = mesh.boundaryMesh();
    labelList patchOf(mesh.nPoints(), -1);
    forAllReverse(pbm, patchi)
    {
        const polyPatch& pp = pbm[patchi];
        if (!isA<coupledPolyPatch>(pp) && !isA<emptyPolyPatch>(pp))
        {
            UIndirectList<label>(patchOf, pp.meshPoints()) = patchi;
        }
    }
    UIndirectList<label>(patchOf, mesh.globalData().coupledPatch().meshPoints()) = -1;
    DynamicList<label> points;
    forAll(patchOf, pointi)
    {
        if (patchOf[pointi] >= 0)
        {
            points.append(pointi);
        }
    }
    std::sort
    (
        points.begin(),
        points.end(),
        [&](const label a, const label b) { return before(points0[a], points0[b]); }
    );
    const pointField x(points0, points);

    // Each rank sends the points within the bounding boxes of the higher
    // ranks' to them (each pair of copies found once, by the higher rank)
    const label myProc = Pstream::myProcNo();
    List<boundBox> rankBox(Pstream::nProcs());
    rankBox[myProc] = boundBox(x, false);
    Pstream::gatherList(rankBox);
    Pstream::scatterList(rankBox);
    PstreamBuffers buffers(Pstream::commsTypes::nonBlocking);
    for (label proci = myProc + 1; proci < Pstream::nProcs(); ++proci)
    {
        DynamicList<point> xs;
        DynamicList<label> patches;
        forAll(x, i)
        {
            if (rankBox[proci].contains(x[i]))
            {
                xs.append(x[i]);
                patches.append(patchOf[points[i]]);
            }
        }
        UOPstream os(proci, buffers);
        os << xs << patches;
    }
    buffers.finishedSends();
    label nCopies = 0;
    boolList named(pbm.size(), false);
    for (label proci = 0; proci < myProc; ++proci)
    {
        UIPstream is(proci, buffers);
        List<point> xs;
        labelList patches;
        is >> xs >> patches;
        forAll(xs, i)
        {
            const auto at = std::lower_bound(x.begin(), x.end(), xs[i], before);
            if (at != x.end() && *at == xs[i])
            {
                ++nCopies;
                named[patches[i]] = true;
                named[patchOf[points[at - x.begin()]]] = true;
            }
        }
    }
    reduce(nCopies, sumOp<label>());
    if (nCopies == 0)
    {
        return;
    }
    Pstream::listCombineGather(named, orEqOp<bool>());
    Pstream::listCombineScatter(named);
    OStringStream names;
    forAll(named, patchi)
    {
        if (named[patchi])
        {
            names<< (names.str().empty() ? "(" : " ") << pbm[patchi].name();
        }
    }
    WarningInFunction
        << nCopies << " boundary points of the patches " << names.str().c_str()
        << ")"
        << " lie on two ranks with no processor face joining them: a baffle"
        << " that a processor boundary runs along (unless the mesh has two"
        << " points there itself: split baffles, meshes merged without"
        << " stitching). Each rank's copy is a"
        << " control point of its own, so the result differs from a serial"
        << " run's, and where the baffle's two sides move differently each"
        << " copy moves with its own side. Decompose with constraints"
        << " { baffles { type preserveBaffles; } } in"
        << " system/decomposeParDict to keep each baffle on one rank" << endl;
}


// ************************************************************************* //
