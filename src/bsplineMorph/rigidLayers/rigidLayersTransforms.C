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

#include "rigidLayers.H"
#include "sharedPoints.H"

#include <algorithm>
#include <cstring>

// The walls' transforms at a step: each wall point's rotation, fitted from
// its faces on the moved wall and smoothed, and its displacement, in the
// feet's compact numbering

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace Foam
{
namespace
{
    //- Twice the area vector of a face of the given points (the triangles
    //  about its first vertex)
    vector twiceArea(const face& f, const pointField& p0, const vectorField* u)
    {
        const point a = u ? p0[f[0]] + (*u)[f[0]] : p0[f[0]];
        vector area(Zero);
        point b = u ? p0[f[1]] + (*u)[f[1]] : p0[f[1]];
        for (label i = 2; i < f.size(); ++i)
        {
            const point c = u ? p0[f[i]] + (*u)[f[i]] : p0[f[i]];
            area += (b - a) ^ (c - a);
            b = c;
        }
        return area;
    }

    //- The normal at vertex v of a face of the given points, weighted as
    //  Max (1999): the cross product of its two edges there over the
    //  product of their squared lengths. Summed over a point's faces it is
    //  exactly the normal of a sphere through the point and its neighbours,
    //  however unevenly they are spaced (and of a cylinder where they lie
    //  around the point and along the axis; Max, Weights for computing
    //  vertex normals from facet normals, J. Graphics Tools 4(2), 1999;
    //  on faces whose two edges at the vertex differ in length by less than
    //  a hundred times)
    vector cornerNormal
    (
        const face& f,
        const label v,
        const pointField& p0,
        const vectorField* u
    )
    {
        const auto at = [&](const label p) { return u ? p0[p] + (*u)[p] : p0[p]; };
        const point x = at(f[v]);
        const vector prev = at(f.prevLabel(v)) - x;
        const vector next = at(f.nextLabel(v)) - x;
        // (an edge shorter than a hundredth of the other weighs as one that
        // long: a near-degenerate face's round-off does not set the normal)
        const scalar p2 = magSqr(prev), n2 = magSqr(next);
        const scalar least = 1e-4*max(p2, n2);
        return (next ^ prev)/(max(p2, least)*max(n2, least) + VSMALL);
    }
}
}



// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::rigidLayers::fitRotations
(
    const pointField& points0,
    const vectorField& displacement,
    const boolList* known
)
{
    // Per wall point: M = sum over its faces on the listed patches of
    // e1 e0^T over the face's edges and A1 A0^T/|A0| (A: area vector;
    // 0: points0, 1: moved); a rigid motion R gives M = R S, S symmetric
    // positive definite, whose polar factor is R. With known: only the
    // faces all of whose points are known
    const polyBoundaryMesh& pbm = mesh_.boundaryMesh();
    const label nWall = wallPoints_.size();
    rotation_.setSize(nWall);
    rotation_ = Zero;
    tensorField patchSum(patchIDs_.size(), Zero);
    label wallFacei = 0;
    forAll(patchIDs_, k)
    {
        for (const face& f : pbm[patchIDs_[k]])
        {
            const label start = wallFaceStart_[wallFacei];
            const label end = wallFaceStart_[++wallFacei];
            if (known && !std::all_of(f.begin(), f.end(), [&](label p) { return (*known)[p]; }))
            {
                continue;
            }
            tensor M(Zero);
            const vector A0 = twiceArea(f, points0, nullptr);
            const vector A1 = twiceArea(f, points0, &displacement);
            // (edge i of the face, from points0 and moved)
            vector e0, e1;
            const auto edgeAt = [&](const label edgei)
            {
                const label a = f[edgei];
                const label b = f.nextLabel(edgei);
                e0 = points0[b] - points0[a];
                e1 = e0 + displacement[b] - displacement[a];
            };
            if (planeOf_.empty())
            {
                forAll(f, edgei)
                {
                    edgeAt(edgei);
                    M += e1*e0;
                }
                M += (A1*A0)/(mag(A0) + VSMALL);
            }
            else
            {
                // A 2D mesh's face spans its arbitrary thickness: its edges
                // across it and its normal weigh as its edges in the plane
                // (their mean length), as a square face's would
                scalar in0 = 0, in1 = 0;
                label nIn = 0;
                forAll(f, edgei)
                {
                    if (!across(f[edgei], f.nextLabel(edgei)))
                    {
                        edgeAt(edgei);
                        M += e1*e0;
                        in0 += mag(e0);
                        in1 += mag(e1);
                        ++nIn;
                    }
                }
                in0 /= max(nIn, 1);
                in1 /= max(nIn, 1);
                const auto scaled = [](const vector& v, const scalar length)
                {
                    return v*(length/(mag(v) + VSMALL));
                };
                forAll(f, edgei)
                {
                    if (across(f[edgei], f.nextLabel(edgei)))
                    {
                        edgeAt(edgei);
                        M += scaled(e1, in1)*scaled(e0, in0);
                    }
                }
                M += scaled(A1, in1)*scaled(A0, in0);
            }
            for (label i = start; i < end; ++i)
            {
                rotation_[wallFacePoints_[i]] += M;
            }
            patchSum[k] += M;
        }
    }
    // Each patch's rotation as a whole (its faces on all ranks)
    Pstream::listCombineGather(patchSum, plusEqOp<tensor>());
    Pstream::listCombineScatter(patchSum);
    patchRotation_.setSize(patchIDs_.size());
    forAll(patchSum, k)
    {
        patchRotation_[k] = rotationOf(patchSum[k], k, knownPatchSum_, knownPatchRotation_);
    }
    if (known)
    {
        knownPatchSum_ = patchSum;
        knownPatchRotation_ = patchRotation_;
    }
    // The sums of the ranks that share a point, the same on all of them
    wallSum_->sum(rotation_);
    // Averaged over the neighbouring faces again, nSmooth_ times (a ring of
    // faces each): the rotations vary smoothly over about innerDistance of a
    // deforming wall, so that the rigid offsets under a crease do not cross;
    // a rigid motion still gives R times a mean of S, whose polar factor is R.
    // A sweep in two gathers: each face's mean of its points, then each
    // point's mean of its faces' means (over all ranks' faces: summed, synced,
    // then divided; means, so that hundreds of sweeps do not overflow)
    const label nWallFaces = wallFaceStart_.size() - 1;
    faceMeans_.setSize(nWallFaces);
    const sweepFunction sweep = [&](const tensorField& in, tensorField& out)
    {
        for (label facei = 0; facei < nWallFaces; ++facei)
        {
            const label start = wallFaceStart_[facei];
            const label end = wallFaceStart_[facei + 1];
            tensor sum(Zero);
            for (label i = start; i < end; ++i)
            {
                sum += in[wallFacePoints_[i]];
            }
            // (a face none of whose points belong to its patch's kind: no
            // point reads its mean)
            faceMeans_[facei] = end > start ? sum/scalar(end - start) : sum;
        }
        out.setSize(nWall);
        for (label wi = 0; wi < nWall; ++wi)
        {
            tensor sum(Zero);
            for (label i = wallPointStart_[wi]; i < wallPointStart_[wi + 1]; ++i)
            {
                sum += faceMeans_[wallPointFaces_[i]];
            }
            out[wi] = sum;
        }
        wallSum_->sum(out);
        forAll(out, wi)
        {
            out[wi] *= wallPointWeight_[wi];
        }
    };
    power(rotation_, nSmooth_, smoothCoeffs_, sweep, smoothWork_);
    const tensorField matrices(known ? rotation_ : tensorField());
    forAll(rotation_, wi)
    {
        rotation_[wi] = rotationOf(rotation_[wi], wi, knownMatrix_, knownRotation_);
    }
    if (known)
    {
        knownMatrix_ = matrices;
        knownRotation_ = rotation_;
    }
    // A wall projected onto one smooth surface keeps its shape while its
    // points slide over it, so that its normals are known where the fitted
    // and smoothed rotation (which takes in the shear of an uneven slide)
    // turns them less or more: each point's rotation turned further by the
    // least rotation that carries its rotated normal onto the moved normal,
    // so that its layers leave the moved wall straight (the fitted turn
    // about the normal kept). (Not over facets or edges, smoothWall_: there
    // the normal turns abruptly, and the smoothed fit keeps the layers from
    // doing so.) Not in a fit from the known faces alone: a projected
    // wall's points are known after the fit only.
    if (!known && smoothSurface_.found(true))
    {
        const vectorField normal1(wallNormals(smoothSurface_, points0, &displacement));
        for (const label wi : smoothWall_)
        {
            const scalar m0 = mag(wallNormal0_[wi]);
            const scalar m1 = mag(normal1[wi]);
            if (m0 > VSMALL && m1 > VSMALL)
            {
                const vector n = (rotation_[wi] & wallNormal0_[wi])/m0;
                const vector n1 = normal1[wi]/m1;
                if ((n & n1) > 0)
                {
                    rotation_[wi] = rotationTensor(n, n1) & rotation_[wi];
                }
            }
        }
    }
}


Foam::vectorField Foam::rigidLayers::wallNormals
(
    const boolList& patches,
    const pointField& points0,
    const vectorField* displacement
) const
{
    vectorField normal(wallPoints_.size(), Zero);
    const polyBoundaryMesh& pbm = mesh_.boundaryMesh();
    label wallFacei = 0;
    forAll(patchIDs_, k)
    {
        for (const face& f : pbm[patchIDs_[k]])
        {
            const label start = wallFaceStart_[wallFacei];
            const label end = wallFaceStart_[++wallFacei];
            // (the face's points of its patch's kind are in face order)
            for (label v = 0, i = start; patches[k] && i < end && v < f.size(); ++v)
            {
                if (wallPoints_[wallFacePoints_[i]] == f[v])
                {
                    normal[wallFacePoints_[i]] += cornerNormal(f, v, points0, displacement);
                    ++i;
                }
            }
        }
    }
    wallSum_->sum(normal);
    return normal;
}


Foam::tensor Foam::rigidLayers::rotationOf
(
    const tensor& M,
    const label i,
    const tensorField& matrices,
    const tensorField& rotations
)
{
    // (bit for bit: rotation() of the same bits gives the same bits)
    if (i < rotations.size() && std::memcmp(&M, &matrices[i], sizeof(tensor)) == 0)
    {
        return rotations[i];
    }
    return rotation(M);
}


void Foam::rigidLayers::fitMovedWalls
(
    const pointField& points0,
    const vectorField& from0
)
{
    fitRotations(points0, from0);
    footDisplacement_ = vectorField(from0, wallPoints_);
    if (anyPair_)
    {
        turnWithPairs();
    }
    mapPtr_->distribute(rotation_);
    mapPtr_->distribute(footDisplacement_);
}


void Foam::rigidLayers::turnWithPairs()
{
    // (the other wall's feet may be on other ranks: the rotations in the
    // feet's compact numbering first)
    tensorField compact(rotation_);
    mapPtr_->distribute(compact);
    forAll(pairWall_, k)
    {
        const label i = pairWall_[k];
        rotation_[zoneFoot_[i]] =
            twist(compact[pairFoot_[zonePair_[i]]], pairWallNormal_[k]);
    }
}


// ************************************************************************* //
