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

#include "sharedPoints.H"
#include "globalMeshData.H"
#include "globalIndex.H"
#include "coupledPolyPatch.H"
#include "processorPolyPatch.H"
#include "processorCyclicPolyPatch.H"

// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::sharedPoints::sharedPoints
(
    const polyMesh& mesh,
    const labelList& meshPoints,
    const bool collocated
)
:
    mesh_(mesh),
    meshPoints_(meshPoints),
    general_(false),
    toOwner_(Pstream::nProcs()),
    fromHolder_(Pstream::nProcs())
{
    // Copies related by a transform (mergePoints joins collocated ones
    // only), on one rank too: a cyclic pair's points combine as they do
    // when the pair is split over ranks
    for (const polyPatch& pp : mesh.boundaryMesh())
    {
        if
        (
            !collocated
         && isA<coupledPolyPatch>(pp)
         && (!isA<processorPolyPatch>(pp) || isA<processorCyclicPolyPatch>(pp))
        )
        {
            general_ = true;
        }
    }
    reduce(general_, orOp<bool>());
    if (general_ || !Pstream::parRun())
    {
        return;
    }

    // A global number per shared point, held by its owner
    Map<label> indexOf(2*meshPoints.size());
    forAll(meshPoints, i)
    {
        indexOf.insert(meshPoints[i], i);
    }
    labelList pointToGlobal;
    labelList uniqueMeshPoints;
    const autoPtr<globalIndex> numbering =
        mesh.globalData().mergePoints
        (
            meshPoints, indexOf, pointToGlobal, uniqueMeshPoints
        );
    List<DynamicList<label>> toOwner(Pstream::nProcs());
    List<DynamicList<label>> ids(Pstream::nProcs());
    forAll(meshPoints, i)
    {
        const label owner = numbering->whichProcID(pointToGlobal[i]);
        if (owner != Pstream::myProcNo())
        {
            toOwner[owner].append(i);
            ids[owner].append(pointToGlobal[i]);
        }
    }
    // The owners learn which of their points each holder sends (sizes
    // they do not know yet: the communicator's exchange of arrays)
    std::vector<std::vector<label>> send(Pstream::nProcs());
    forAll(ids, proci)
    {
        toOwner_[proci].transfer(toOwner[proci]);
        send[proci].assign(ids[proci].begin(), ids[proci].end());
    }
    const std::vector<std::vector<label>> got = comm_.exchange(send);
    forAll(fromHolder_, proci)
    {
        labelList& at = fromHolder_[proci];
        at.setSize(got[proci].size());
        forAll(at, k)
        {
            at[k] = indexOf[uniqueMeshPoints[numbering->toLocal(got[proci][k])]];
        }
    }
}


// ************************************************************************* //
