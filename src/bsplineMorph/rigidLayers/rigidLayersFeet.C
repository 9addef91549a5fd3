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
#include "globalIndex.H"
#include "PstreamBuffers.H"
#include "indexedOctree.H"
#include "treeDataPoint.H"
#include "hugePageLists.H"

#include <vector>

// The rigid layers' feet, once per topology: each zone point's nearest wall
// point (also on nearby ranks) and, where another listed wall is near too,
// its nearest point there

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace Foam
{
namespace
{
    //- Squared distance from a point to a box (0 inside; large for an
    //  empty box)
    scalar distSqrToBox(const point& p, const boundBox& bb)
    {
        if (bb.empty())
        {
            return GREAT;
        }
        scalar s = 0;
        for (direction d = 0; d < 3; ++d)
        {
            const scalar below = bb.min()[d] - p[d];
            const scalar above = p[d] - bb.max()[d];
            const scalar out = max(below, above);
            if (out > 0)
            {
                s += out*out;
            }
        }
        return s;
    }

    //- The candidates' positions: the first n of them
    template<class Candidate>
    pointField positionsOf(const std::vector<Candidate>& cand, const label n)
    {
        pointField points(n);
        forAll(points, c)
        {
            points[c] = cand[c].x;
        }
        return points;
    }

    //- An octree of the points (held by reference), their box bb grown by
    //  margin
    autoPtr<indexedOctree<treeDataPoint>> pointTree
    (
        const pointField& points,
        const treeBoundBox& bb,
        const scalar margin
    )
    {
        return autoPtr<indexedOctree<treeDataPoint>>::New
        (
            treeDataPoint(points),
            treeBoundBox(bb.min() - vector::one*margin, bb.max() + vector::one*margin),
            10,     // levels
            10,     // candidates per leaf
            3       // duplicity
        );
    }

    //- Whether foot a is preferred to foot b at the same squared distance:
    //  the lexicographically smaller point, then a copy on this rank (the
    //  same point on two ranks has the same transform)
    template<class Candidate>
    bool preferred(const Candidate& a, const Candidate& b)
    {
        for (direction d = 0; d < 3; ++d)
        {
            if (a.x[d] != b.x[d])
            {
                return a.x[d] < b.x[d];
            }
        }
        return a.local && !b.local;
    }

    //- The octree's nearest-point search with equal squared distances going
    //  to preferred(): the octree visits every box no farther than the
    //  nearest so far, so that one traversal meets every tie
    template<class Candidate>
    class nearestPreferredOp
    {
        const std::vector<Candidate>& cand_;

    public:

        explicit nearestPreferredOp(const std::vector<Candidate>& cand)
        :
            cand_(cand)
        {}

        void operator()
        (
            const labelUList& indices,
            const point& sample,
            scalar& nearestDistSqr,
            label& minIndex,
            point& nearestPoint
        ) const
        {
            for (const label c : indices)
            {
                const scalar distSqr = magSqr(sample - cand_[c].x);
                if
                (
                    distSqr < nearestDistSqr
                 || (
                        distSqr == nearestDistSqr && minIndex >= 0
                     && preferred(cand_[c], cand_[minIndex])
                    )
                )
                {
                    nearestDistSqr = distSqr;
                    minIndex = c;
                    nearestPoint = cand_[c].x;
                }
            }
        }
    };
}
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

std::vector<Foam::rigidLayers::footCandidate> Foam::rigidLayers::footCandidates
(
    const pointField& points0,
    const globalIndex& wallIndex,
    const labelList& pointPatch,
    const vectorField& wallNormal,
    label& nNearest
) const
{
    const label myProc = Pstream::myProcNo();
    // Candidate feet: this rank's wall points and those of the other ranks
    // within outerDistance of this rank's points, each with the first
    // listed patch that holds it (the nearest foot's candidates); then the
    // same again for the other listed patches that hold it (where walls
    // meet: candidates of the feet on another wall only); with two listed
    // patches or more those within twice outerDistance (a point's nearest
    // foot on another wall, for the gaps between walls that face each
    // other: findFeet())
    const scalar reach = (patchIDs_.size() > 1 ? 2 : 1)*outerDistance_;
    const auto normalOf = [&](const label wi)
    {
        return wallNormal.size() ? wallNormal[wi] : vector::zero;
    };
    List<boundBox> rankBox(Pstream::nProcs());
    rankBox[myProc] = boundBox(points0, false);
    Pstream::gatherList(rankBox);
    Pstream::scatterList(rankBox);

    // This rank's (wall point, patch) pairs: the first patches, then others
    DynamicList<label> wall(wallPoints_.size()), patch(wallPoints_.size());
    forAll(wallPoints_, i)
    {
        wall.append(i);
        patch.append(pointPatch[wallPoints_[i]]);
    }
    const label nFirst = wall.size();
    if (patchIDs_.size() > 1)
    {
        labelList wallOf(mesh_.nPoints(), -1);
        UIndirectList<label>(wallOf, wallPoints_) = identity(wallPoints_.size());
        forAll(patchIDs_, k)
        {
            for (const label pointi : mesh_.boundaryMesh()[patchIDs_[k]].meshPoints())
            {
                if (pointPatch[pointi] != k)
                {
                    wall.append(wallOf[pointi]);
                    patch.append(k);
                }
            }
        }
    }

    std::vector<footCandidate> cand, others;
    cand.reserve(wallPoints_.size());
    forAll(wall, c)
    {
        (c < nFirst ? cand : others).push_back
        (
            {
                wallIndex.toGlobal(wall[c]), points0[wallPoints_[wall[c]]],
                patch[c], true, normalOf(wall[c])
            }
        );
    }
    if (Pstream::parRun())
    {
        PstreamBuffers buffers(Pstream::commsTypes::nonBlocking);
        for (label proci = 0; proci < Pstream::nProcs(); ++proci)
        {
            if (proci == myProc)
            {
                continue;
            }
            DynamicList<label> ids, patches;
            DynamicList<point> xs;
            DynamicList<vector> ns;
            label nSentFirst = 0;
            forAll(wall, c)
            {
                const point& x = points0[wallPoints_[wall[c]]];
                if (distSqrToBox(x, rankBox[proci]) <= reach*reach)
                {
                    ids.append(wallIndex.toGlobal(wall[c]));
                    xs.append(x);
                    patches.append(patch[c]);
                    ns.append(normalOf(wall[c]));
                    nSentFirst += c < nFirst;
                }
            }
            UOPstream os(proci, buffers);
            os << ids << xs << patches << ns << nSentFirst;
        }
        buffers.finishedSends();
        for (label proci = 0; proci < Pstream::nProcs(); ++proci)
        {
            if (proci == myProc)
            {
                continue;
            }
            UIPstream is(proci, buffers);
            labelList ids, patches;
            List<point> xs;
            List<vector> ns;
            label nSentFirst;
            is >> ids >> xs >> patches >> ns >> nSentFirst;
            forAll(ids, c)
            {
                (c < nSentFirst ? cand : others).push_back
                (
                    {ids[c], xs[c], patches[c], false, ns[c]}
                );
            }
        }
    }
    nNearest = label(cand.size());
    cand.insert(cand.end(), others.begin(), others.end());

    return cand;
}


void Foam::rigidLayers::findFeet
(
    const pointField& points0,
    const std::vector<footCandidate>& cand,
    const label nNearest,
    const labelList& kind
)
{
    // The candidates in an octree: each point's nearest one within
    // outerDistance (equal distances go to preferred())
    zonePoints_.clear();
    zoneFoot_.clear();
    zoneWeight_.clear();
    zoneArm_.clear();
    zonePair_.clear();
    pairFoot_.clear();
    pairArm_.clear();
    pairShare_.clear();
    pairFollows_.clear();
    facingGaps_.clear();
    if (nNearest == 0)
    {
        return;
    }
    const pointField candPoints(positionsOf(cand, nNearest));
    const treeBoundBox candBox(candPoints);
    const autoPtr<indexedOctree<treeDataPoint>> treePtr
    (
        pointTree(candPoints, candBox, outerDistance_)
    );
    const indexedOctree<treeDataPoint>& tree = *treePtr;

    // and per listed patch its candidates in an octree, for a point's
    // nearest foot on another wall than its nearest foot's (2 or more
    // listed patches)
    const label nPatches = patchIDs_.size() > 1 ? patchIDs_.size() : 0;
    std::vector<std::vector<footCandidate>> patchCand(nPatches);
    for (const footCandidate& c : cand)
    {
        if (nPatches)
        {
            patchCand[c.patch].push_back(c);
        }
    }
    List<pointField> patchPoints(nPatches);
    List<treeBoundBox> patchBox(nPatches);
    PtrList<indexedOctree<treeDataPoint>> patchTree(nPatches);
    for (label k = 0; k < nPatches; ++k)
    {
        patchPoints[k] = positionsOf(patchCand[k], label(patchCand[k].size()));
        if (patchPoints[k].empty())
        {
            continue;
        }
        patchBox[k] = treeBoundBox(patchPoints[k]);
        patchTree.set(k, pointTree(patchPoints[k], patchBox[k], outerDistance_));
    }

    DynamicList<label> zone, feet, zonePair, pairFeet;
    DynamicList<bool> follows;
    DynamicList<scalar> weights, shares;
    DynamicList<vector> arms, pairArms;
    const scalar outerSqr = sqr(outerDistance_);
    const nearestPreferredOp<footCandidate> nearest(cand);
    forAll(points0, pointi)
    {
        const point& x = points0[pointi];
        if (distSqrToBox(x, candBox) >= outerSqr)
        {
            continue;   // (most points of a large mesh: no search)
        }
        const pointIndexHit hit = tree.findNearest(x, outerSqr, nearest);
        if (!hit.hit())
        {
            continue;
        }
        const label best = hit.index();
        const scalar bestSqr = magSqr(x - cand[best].x);
        zone.append(pointi);
        feet.append(cand[best].globalIndex);
        const scalar d = std::sqrt(bestSqr);
        weights.append(weight(d, innerDistance_, outerDistance_));
        arms.append(x - cand[best].x);

        // The nearest foot on another listed wall (ties: the first listed
        // wall, then preferred()), within 2 outerDistance - d, where the
        // gap between the walls, if they face each other there, is
        // narrower than twice outerDistance; and if it is nearer than
        // d + width (width: innerDistance, less where that would reach
        // past outerDistance) the point's pair foot
        const scalar width = min(innerDistance_, outerDistance_ - d);
        label pairPatch = -1;
        label pairBest = -1;
        scalar pairSqr = sqr(max(d + width, 2*outerDistance_ - d));
        for (label k = 0; k < nPatches; ++k)
        {
            if
            (
                k == cand[best].patch || !patchTree.set(k)
             || distSqrToBox(x, patchBox[k]) >= pairSqr
            )
            {
                continue;
            }
            const pointIndexHit pairHit = patchTree[k].findNearest
            (
                x,
                pairSqr,
                nearestPreferredOp<footCandidate>(patchCand[k])
            );
            // (the nearest foot itself, where it is on this wall too,
            // stands for it)
            if (pairHit.hit() && patchCand[k][pairHit.index()].x != cand[best].x)
            {
                pairPatch = k;
                pairBest = pairHit.index();
                pairSqr = magSqr(x - patchCand[k][pairBest].x);
            }
        }
        if (pairPatch >= 0)
        {
            noteFacingGap(cand[best], patchCand[pairPatch][pairBest], x);
        }
        if (pairPatch >= 0 && pairSqr < sqr(d + width))
        {
            const footCandidate& c = patchCand[pairPatch][pairBest];
            zonePair.resize(zone.size(), -1);
            zonePair.last() = pairFeet.size();
            pairFeet.append(c.globalIndex);
            // (a point's first candidate's patch is its own patch)
            follows.append(kind[pairPatch] <= kind[cand[best].patch]);
            pairArms.append(x - c.x);
            shares.append(pairShare(d, std::sqrt(pairSqr), width));
        }
    }
    zonePoints_.transfer(zone);
    zoneFoot_.transfer(feet);
    zoneWeight_.transfer(weights);
    zoneArm_.transfer(arms);
    if (pairFeet.size())
    {
        zonePair.resize(zonePoints_.size(), -1);
    }
    zonePair_.transfer(zonePair);
    pairFoot_.transfer(pairFeet);
    pairArm_.transfer(pairArms);
    pairShare_.transfer(shares);
    pairFollows_ = bitSet(follows);
    // (swept at every step)
    onHugePages(zonePoints_);
    onHugePages(zoneFoot_);
    onHugePages(zoneWeight_);
    onHugePages(zoneArm_);
}


// ************************************************************************* //
