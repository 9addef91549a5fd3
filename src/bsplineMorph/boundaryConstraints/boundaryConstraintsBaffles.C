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
#include "labelIOList.H"

#include <algorithm>
#include <utility>
#include <vector>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    using namespace Foam;

    // Lexicographic order of points (copies of a point are equal bit for bit)
    bool before(const point& a, const point& b)
    {
        return
            a.x() < b.x()
         || (a.x() == b.x() && (a.y() < b.y() || (a.y() == b.y() && a.z() < b.z())));
    }

    // A copy of a boundary point: where, on which rank, its global point
    // (processor faces join copies into one), its point in the undecomposed
    // mesh (-1: not known) and its patch
    struct pointCopy
    {
        point x;
        label rank;
        label global;
        label original;
        label patch;
    };

    // Each point's label in the undecomposed mesh, from the
    // pointProcAddressing that decomposePar wrote beside this mesh's faces,
    // where every rank has one of its size (false: none; snappyHexMesh
    // -parallel and other topology changes leave none there, or one of the
    // old mesh's size) (collective)
    bool undecomposedPoints(const polyMesh& mesh, labelList& original)
    {
        IOobject io
        (
            "pointProcAddressing",
            mesh.facesInstance(),
            mesh.meshSubDir,
            mesh,
            IOobject::MUST_READ,
            IOobject::NO_WRITE,
            false
        );
        original.clear();
        const bool found =
            returnReduce(io.typeHeaderOk<labelIOList>(true), andOp<bool>());
        if (found)
        {
            original = labelIOList(io);
        }
        // (a rank without points has an empty list: known all the same)
        return
            found
         && returnReduce(original.size() == mesh.nPoints(), andOp<bool>());
    }

    // How many different labels
    label nDistinct(std::vector<label>& labels)
    {
        std::sort(labels.begin(), labels.end());
        return std::unique(labels.begin(), labels.end()) - labels.begin();
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
    // This rank's points of patches that are not couplings (a cyclicAMI's
    // sides are separate points however decomposed) nor empty, with the
    // first such patch that holds them and their global point
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
    labelList toGlobal, unique;
    mesh.globalData().mergePoints(toGlobal, unique);
    labelList original;
    const bool known = undecomposedPoints(mesh, original);
    const label myProc = Pstream::myProcNo();
    std::vector<pointCopy> copies;
    forAll(patchOf, pointi)
    {
        if (patchOf[pointi] >= 0)
        {
            copies.push_back
            ({
                points0[pointi],
                myProc,
                toGlobal[pointi],
                known ? original[pointi] : -1,
                patchOf[pointi]
            });
        }
    }
    boundBox box;
    for (const pointCopy& c : copies)
    {
        box.add(c.x);
    }

    // Each rank sends those within another rank's bounding box to it: a
    // rank gets every copy of each of its points (once a run: a few
    // points per rank where the ranks are boxes or slabs, more where
    // their boxes overlap much)
    List<boundBox> rankBox(Pstream::nProcs());
    rankBox[myProc] = box;
    Pstream::gatherList(rankBox);
    Pstream::scatterList(rankBox);
    PstreamBuffers buffers(Pstream::commsTypes::nonBlocking);
    const label nMine = label(copies.size());
    for (label proci = 0; proci < Pstream::nProcs(); ++proci)
    {
        if (proci == myProc)
        {
            continue;
        }
        DynamicList<point> xs;
        DynamicList<label> globals, originals, patches;
        for (label i = 0; i < nMine; ++i)
        {
            if (rankBox[proci].contains(copies[i].x))
            {
                xs.append(copies[i].x);
                globals.append(copies[i].global);
                originals.append(copies[i].original);
                patches.append(copies[i].patch);
            }
        }
        UOPstream os(proci, buffers);
        os << xs << globals << originals << patches;
    }
    buffers.finishedSends();
    for (label proci = 0; proci < Pstream::nProcs(); ++proci)
    {
        if (proci == myProc)
        {
            continue;
        }
        UIPstream is(proci, buffers);
        List<point> xs;
        labelList globals, originals, patches;
        is >> xs >> globals >> originals >> patches;
        forAll(xs, i)
        {
            copies.push_back({xs[i], proci, globals[i], originals[i], patches[i]});
        }
    }

    // Each place with a copy here, counted by the lowest rank that has one:
    // split where it has more global points than the undecomposed mesh has
    // points there, or, where that is not known, than any rank holds there
    // (a rank that holds two has two points in the mesh itself: split
    // baffles). Copies of one global point with different undecomposed
    // points: the addressing is not this mesh's, and is not used (so too
    // where a collocated cyclic, which mergePoints merges, joins them: the
    // count then is the ranks')
    std::sort
    (
        copies.begin(),
        copies.end(),
        [](const pointCopy& a, const pointCopy& b)
        {
            return
                before(a.x, b.x)
             || (a.x == b.x && (a.rank < b.rank || (a.rank == b.rank && a.global < b.global)));
        }
    );
    label nSplit[2] = {0, 0};      // by the undecomposed mesh, by the ranks
    bool stale = false;
    List<boolList> named(2, boolList(pbm.nNonProcessor(), false));
    std::vector<label> globals, originals;
    std::vector<std::pair<label, label>> pairs;
    for (std::size_t i = 0, j; i < copies.size(); i = j)
    {
        globals.clear();
        originals.clear();
        label mostOnRank = 0, onRank = 0;
        for (j = i; j < copies.size() && copies[j].x == copies[i].x; ++j)
        {
            globals.push_back(copies[j].global);
            originals.push_back(copies[j].original);
            onRank = j > i && copies[j].rank == copies[j - 1].rank ? onRank + 1 : 1;
            mostOnRank = max(mostOnRank, onRank);
        }
        if (copies[i].rank != myProc)
        {
            continue;
        }
        const label nGlobal = nDistinct(globals);
        const label nOriginal = nDistinct(originals);
        if (known)
        {
            pairs.clear();
            for (std::size_t k = i; k < j; ++k)
            {
                pairs.push_back({copies[k].global, copies[k].original});
            }
            std::sort(pairs.begin(), pairs.end());
            stale = stale || std::unique(pairs.begin(), pairs.end()) - pairs.begin() > nGlobal;
        }
        const bool split[2] = {known && nGlobal > nOriginal, nGlobal > mostOnRank};
        for (const label by : {0, 1})
        {
            if (split[by])
            {
                ++nSplit[by];
                for (std::size_t k = i; k < j; ++k)
                {
                    named[by][copies[k].patch] = true;
                }
            }
        }
    }
    const label by = known && !returnReduce(stale, orOp<bool>()) ? 0 : 1;
    const label nSplitBy = returnReduce(nSplit[by], sumOp<label>());
    if (nSplitBy == 0)
    {
        return;
    }
    boolList& namedBy = named[by];
    Pstream::listCombineGather(namedBy, orEqOp<bool>());
    Pstream::listCombineScatter(namedBy);
    OStringStream names;
    forAll(namedBy, patchi)
    {
        if (namedBy[patchi])
        {
            names<< (names.str().empty() ? "(" : " ") << pbm[patchi].name();
        }
    }
    WarningInFunction
        << nSplitBy << " boundary points of the patches " << names.str().c_str()
        << ") lie on several ranks with no processor face joining them: a"
        << " baffle that a processor boundary runs along"
        << (
               by == 0 ? ""
             : " (unless the mesh has separate points there itself: split"
               " baffles, meshes merged without stitching; no"
               " pointProcAddressing of this mesh from decomposePar tells)"
           )
        << ". Each rank's copy is a point of its own:"
        << " where the baffle's sides move differently each copy moves with"
        << " its own side (in a serial run the one point moves with the"
        << " later patch), and multilevelBSpline's fit counts each copy as a"
        << " control point, so its result differs from a serial run's even"
        << " where they move alike. Decompose with constraints { baffles"
        << " { type preserveBaffles; } } in system/decomposeParDict to keep"
        << " each baffle on one rank" << endl;
}


// ************************************************************************* //
