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
#include "boundaryConstraints.H"
#include "emptyPolyPatch.H"
#include "wedgePolyPatch.H"
#include "syncTools.H"
#include "globalIndex.H"
#include "bitSet.H"
#include "HashOps.H"
#include "Map.H"
#include "OStringStream.H"
#include "unitConversion.H"

#include <algorithm>
#include <cmath>
#include <vector>

// The plan of the rigid layers, once per topology: the walls' points, the
// zone's outermost points (its feet: rigidLayersFeet.C), and the warning
// about fixed walls in the zone

// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

bool Foam::rigidLayers::isWall(const polyPatch& pp)
{
    return
        !pp.coupled()
     && !isA<emptyPolyPatch>(pp)
     && !isA<wedgePolyPatch>(pp);
}


void Foam::rigidLayers::findWallPoints
(
    const pointField& points0,
    const labelList& pointPatch,
    const labelList& kind
)
{
    const polyBoundaryMesh& pbm = mesh_.boundaryMesh();
    // The wall points, and where each listed patch's points are among them
    bitSet onWall(mesh_.nPoints());
    for (const label patchi : patchIDs_)
    {
        onWall.set(pbm[patchi].meshPoints());
    }
    wallPoints_ = onWall.sortedToc();
    // A 2D mesh's two planes: across its empty direction (whether one
    // empty patch holds both or each has its own), else its wedge patches
    planeOf_.clear();
    const Vector<label>& solutionD = mesh_.solutionD();
    const label emptyDir =
        solutionD.x() < 0 ? 0 : solutionD.y() < 0 ? 1 : solutionD.z() < 0 ? 2 : -1;
    if (emptyDir >= 0)
    {
        scalar lo = GREAT, hi = -GREAT;
        for (const point& p : points0)
        {
            lo = min(lo, p[emptyDir]);
            hi = max(hi, p[emptyDir]);
        }
        reduce(lo, minOp<scalar>());
        reduce(hi, maxOp<scalar>());
        const scalar mid = 0.5*(lo + hi);
        planeOf_.setSize(mesh_.nPoints());
        forAll(points0, pointi)
        {
            planeOf_[pointi] = points0[pointi][emptyDir] < mid ? 0 : 1;
        }
    }
    else
    {
        for (const polyPatch& pp : pbm)
        {
            if (isA<wedgePolyPatch>(pp))
            {
                planeOf_.setSize(mesh_.nPoints(), -1);
                for (const label pointi : pp.meshPoints())
                {
                    planeOf_[pointi] = planeOf_[pointi] == -1 ? pp.index() : -2;
                }
            }
        }
    }
    Map<label> wallOf(2*wallPoints_.size());
    forAll(wallPoints_, i)
    {
        wallOf.insert(wallPoints_[i], i);
    }
    // The smoothing of the rotations: an averaging (each point gets the
    // means of its faces' points) spreads them by a variance of about half an
    // edge squared, so (innerDistance/edge)^2 of them, by the walls' mean
    // edge, smooth them over a standard deviation of about
    // innerDistance/sqrt(2); summed from Chebyshev polynomials of the
    // averaging they take about 5 innerDistance/edge sweeps (powerCoeffs)
    scalar edgeSum = 0;
    label nEdges = 0;
    for (const label patchi : patchIDs_)
    {
        // (of the undeformed walls: a restart reads a moved mesh)
        // (in a 2D mesh those in its plane: its thickness is arbitrary)
        // (the faces' sides, an edge inside a patch once for each of its
        // two faces: every face is on one rank, where a patch's edge along
        // a processor boundary is on both)
        for (const face& f : pbm[patchi])
        {
            forAll(f, i)
            {
                const label a = f[i];
                const label b = f.nextLabel(i);
                if (!across(a, b))
                {
                    edgeSum += mag(points0[b] - points0[a]);
                    ++nEdges;
                }
            }
        }
    }
    edgeSum = returnReduce(edgeSum, sumOp<scalar>());
    nEdges = returnReduce(nEdges, sumOp<label>());
    const scalar rings = nEdges && edgeSum > 0 ? innerDistance_*nEdges/edgeSum : 0;
    // (rounded up, but within 1e-9 above a whole number that number: the
    // sum's last bits differ from one decomposition to another, and an
    // innerDistance of a whole number of edges, as often chosen, would
    // round to either)
    nSmooth_ = min(label(std::ceil(rings*rings*(1 - 1e-9))), maxSmooth);
    smoothCoeffs_ = powerCoeffs(nSmooth_, powerTolerance);

    // Each listed face's points whose own patch (pointPatch) is of the
    // face's patch's kind, as indices into wallPoints_: where listed walls
    // of different kinds meet (a moved body on a wall it slides on), a
    // point takes its rotation from the faces of its own patch's kind
    // alone, and the smoothing keeps to them, so that the body keeps its
    // rotation up to the wall; walls of one kind (a deforming wall in
    // several patches) are smoothed across as one wall, so that their
    // rotations do not jump where they meet
    DynamicList<label> start(1, 0);
    DynamicList<label> facePoints;
    forAll(patchIDs_, k)
    {
        for (const face& f : pbm[patchIDs_[k]])
        {
            for (const label pointi : f)
            {
                if (kind[pointPatch[pointi]] == kind[k])
                {
                    facePoints.append(wallOf[pointi]);
                }
            }
            start.append(facePoints.size());
        }
    }
    wallFaceStart_.transfer(start);
    wallFacePoints_.transfer(facePoints);
    // and each wall point's faces (counted, then filled in face order)
    wallPointStart_ = labelList(wallPoints_.size() + 1, Zero);
    for (const label wi : wallFacePoints_)
    {
        ++wallPointStart_[wi + 1];
    }
    for (label wi = 0; wi < wallPoints_.size(); ++wi)
    {
        wallPointStart_[wi + 1] += wallPointStart_[wi];
    }
    wallPointWeight_.setSize(wallPoints_.size());
    forAll(wallPointWeight_, wi)
    {
        wallPointWeight_[wi] = wallPointStart_[wi + 1] - wallPointStart_[wi];
    }
    wallSum_.reset(new sharedPoints(mesh_, wallPoints_));
    wallSum_->sum(wallPointWeight_);
    for (scalar& w : wallPointWeight_)
    {
        w = 1/w;
    }
    wallPointFaces_.setSize(wallFacePoints_.size());
    labelList fill(SubList<label>(wallPointStart_, wallPoints_.size()));
    for (label facei = 0; facei + 1 < wallFaceStart_.size(); ++facei)
    {
        for (label i = wallFaceStart_[facei]; i < wallFaceStart_[facei + 1]; ++i)
        {
            wallPointFaces_[fill[wallFacePoints_[i]]++] = facei;
        }
    }
}



void Foam::rigidLayers::findOutermost()
{
    // The rigid zone's outermost points (within innerDistance, with an edge
    // to a point beyond it): the interpolation's extra control points, those
    // off the patches always, those on patches where addControls() finds
    // that they may be (an axisymmetric mesh's wedge planes are no such
    // patches: its frame keeps their points on them)
    bitSet inner(mesh_.nPoints());
    markRigid(inner);
    // (the edges as the faces' sides: every edge is a side of a face; the
    // mesh's edge list, built on first use, took 0.22 s of the 1M cube's
    // first step, the faces' sides take 0.02 s)
    labelList outermost(mesh_.nPoints(), 0);
    for (const face& f : mesh_.faces())
    {
        forAll(f, i)
        {
            const label a = f[i];
            const label b = f.nextLabel(i);
            if (inner.test(a) != inner.test(b))
            {
                outermost[inner.test(a) ? a : b] = 1;
            }
        }
    }
    syncTools::syncPointList(mesh_, outermost, maxEqOp<label>(), label(0));
    bitSet onPatch(mesh_.nPoints());
    for (const polyPatch& pp : mesh_.boundaryMesh())
    {
        if (isWall(pp))
        {
            onPatch.set(pp.meshPoints());
        }
    }
    DynamicList<label> shell, shellPoints, patchShell;
    forAll(zonePoints_, i)
    {
        const label pointi = zonePoints_[i];
        if (inner.test(pointi) && outermost[pointi])
        {
            if (onPatch.test(pointi))
            {
                patchShell.append(i);
            }
            else
            {
                shell.append(i);
                shellPoints.append(pointi);
            }
        }
    }
    shell_.transfer(shell);
    shellPoints_.transfer(shellPoints);
    patchShell_.transfer(patchShell);

}


void Foam::rigidLayers::plan
(
    const pointField& points0,
    const boundaryConstraints& bc
)
{
    // The listed patches' kinds, by how much of their points' motion their
    // conditions say: 0 fixing it, 1 projecting it onto a surface, 2
    // sliding on planes. Each wall point's own patch: the first listed one
    // that holds it on any rank (the same on every decomposition) of the
    // lowest kind. Where a moved body meets a wall it slides on, the points
    // they share move with the body and take its rotation (the wall's
    // rotation about its normal there is the interpolated field's, or the
    // body's layers')
    const polyBoundaryMesh& pbm = mesh_.boundaryMesh();
    labelList kind(patchIDs_.size());
    forAll(patchIDs_, k)
    {
        const label patchi = patchIDs_[k];
        kind[k] =
            bc.fixesPatch(patchi) ? 0
          : bc.projectingPatches().found(patchi) ? 1
          : 2;
    }
    // (the least of kind*nListed + k over the patches holding the point)
    const label nListed = patchIDs_.size();
    labelList pointPatch(mesh_.nPoints(), labelMax);
    forAll(patchIDs_, k)
    {
        for (const label pointi : pbm[patchIDs_[k]].meshPoints())
        {
            pointPatch[pointi] = min(pointPatch[pointi], kind[k]*nListed + k);
        }
    }
    syncTools::syncPointList(mesh_, pointPatch, minEqOp<label>(), labelMax);
    for (label& k : pointPatch)
    {
        if (k != labelMax)
        {
            k %= nListed;
        }
    }
    smoothSurface_.setSize(kind.size());
    forAll(kind, k)
    {
        smoothSurface_[k] = bc.smoothProjectingPatches().found(patchIDs_[k]);
    }
    findWallPoints(points0, pointPatch, kind);
    // Each wall point's normal in points0, summed over every listed patch's
    // faces: the smooth walls' turn reads it at smoothWall_'s points (whose
    // faces are all of smooth patches), the facing gaps (two listed patches
    // or more) everywhere
    wallNormal0_.clear();
    if (patchIDs_.size() > 1 || smoothSurface_.found(true))
    {
        wallNormal0_ = wallNormals(boolList(patchIDs_.size(), true), points0, nullptr);
    }
    // The wall points whose normal is their smooth surface's: their own
    // patch projects onto one, and none of their faces (on any rank) is of
    // a patch that does not (where such patches meet, the normal from their
    // faces turns abruptly)
    smoothWall_.clear();
    if (smoothSurface_.found(true))
    {
        scalarField rough(wallPoints_.size(), Zero);
        label facei = 0;
        forAll(patchIDs_, k)
        {
            for (label n = pbm[patchIDs_[k]].size(); n > 0; --n, ++facei)
            {
                for (label i = wallFaceStart_[facei]; i < wallFaceStart_[facei + 1]; ++i)
                {
                    rough[wallFacePoints_[i]] += !smoothSurface_[k];
                }
            }
        }
        wallSum_->sum(rough);
        smoothWall_.resize(wallPoints_.size());
        forAll(wallPoints_, wi)
        {
            smoothWall_.set(wi, smoothSurface_[pointPatch[wallPoints_[wi]]] && rough[wi] == 0);
        }
    }
    const globalIndex wallIndex(wallPoints_.size());
    label nNearest = 0;
    const std::vector<footCandidate> cand
    (
        footCandidates(points0, wallIndex, pointPatch, wallNormal0_, nNearest)
    );
    findFeet(points0, cand, nNearest, kind);
    anyPair_ = returnReduce(pairFoot_.size() > 0, orOp<bool>());
    findOutermost();
    // The feet in compact numbering: this rank's wall points, then the other
    // ranks' that are feet here (the nearest feet, then the other walls')
    List<Map<label>> compactMap;
    labelList feet(zoneFoot_);
    feet.append(pairFoot_);
    mapPtr_.reset(new mapDistribute(wallIndex, feet, compactMap));
    forAll(zoneFoot_, i)
    {
        zoneFoot_[i] = feet[i];
    }
    forAll(pairFoot_, p)
    {
        pairFoot_[p] = feet[zoneFoot_.size() + p];
    }
    footPatch_ = labelList(UIndirectList<label>(pointPatch, wallPoints_));
    mapPtr_->distribute(footPatch_);
    planned_ = true;
    const wordList patchNames(pbm.names(), patchIDs_);
    // (each point counted once, however many ranks hold it)
    const boolList owned(ownedPoints(mesh_));
    bitSet inner(mesh_.nPoints());
    markRigid(inner);
    const label sweeps = nSweeps(nSmooth_, smoothCoeffs_);
    // (a wall point where a processor boundary meets the wall may be owned
    // by a rank whose faces there are not the wall's: pointPatch, synced,
    // knows it as a wall point there too)
    label nWall = 0;
    forAll(pointPatch, pointi)
    {
        nWall += pointPatch[pointi] != labelMax && owned[pointi];
    }
    reduce(nWall, sumOp<label>());
    Info<< "rigidLayers: " << nOwnedGlobal(owned, zonePoints_)
        << " points within outerDistance " << outerDistance_ << " of "
        << nWall << " wall points on patches "
        << flatOutput(patchNames)
        << " (" << nOwnedGlobal(owned, inner.toc())
        << " within innerDistance " << innerDistance_ << ", "
        << nOwnedGlobal(owned, shellPoints_)
        << " of them outermost: control points, and "
        << nOwnedGlobal(owned, labelList(UIndirectList<label>(zonePoints_, patchShell_)))
        << " more on patches (outermost too; control points only where their"
        << " conditions slide them and their foot is prescribed); rotations"
        << " smoothed over " << nSmooth_
        << (nSmooth_ == 1 ? " ring" : " rings") << " of faces, in " << sweeps
        << (sweeps == 1 ? " sweep)" : " sweeps)") << endl;
    // (where listed walls meet)
    DynamicList<label> paired, pairedOnWall;
    forAll(zonePair_, i)
    {
        if (zonePair_[i] >= 0)
        {
            paired.append(zonePoints_[i]);
            if (magSqr(zoneArm_[i]) == 0)
            {
                pairedOnWall.append(zonePoints_[i]);
            }
        }
    }
    const label nPaired = nOwnedGlobal(owned, paired);
    if (nPaired)
    {
        Info<< "rigidLayers: " << nPaired << " of those points are near two"
            << " listed walls (where they meet or pass near each other) and"
            << " blend the two walls' rigid"
            << " motions; " << nOwnedGlobal(owned, pairedOnWall)
            << " of them lie on a wall, within innerDistance of the other:"
            << " where their wall slides, they keep to the other wall's layers"
            << endl;
    }
    warnFacingGaps();
}


void Foam::rigidLayers::noteFacingGap
(
    const footCandidate& a,
    const footCandidate& b,
    const point& x
)
{
    // (the normals are the faces' area vectors', out of the mesh: a point
    // in front of a wall lies against its normal; a point on a wall, its
    // arm zero, is in front of it: a gap one cell across has no other)
    const scalar cos30 = std::cos(degToRad(30.0));
    const vector armA = x - a.x;
    const vector armB = x - b.x;
    const auto inFront = [&](const vector& arm, const vector& n)
    {
        return mag(arm) == 0 || (arm & n) < -cos30*mag(arm)*mag(n);
    };
    const scalar gap = mag(armA) + mag(armB);
    if
    (
        gap > 0 && gap < (2 - 1e-9)*outerDistance_
     && (a.n & b.n) < -cos30*mag(a.n)*mag(b.n)
     && inFront(armA, a.n) && inFront(armB, b.n)
    )
    {
        const label n = patchIDs_.size();
        const label key = min(a.patch, b.patch)*n + max(a.patch, b.patch);
        facingGaps_.set(key, min(gap, facingGaps_.lookup(key, GREAT)));
    }
}


void Foam::rigidLayers::warnFacingGaps()
{
    if (facingWarned_ || patchIDs_.size() < 2)
    {
        return;
    }
    Map<scalar> gaps(facingGaps_);
    Pstream::mapCombineGather(gaps, minEqOp<scalar>());
    Pstream::mapCombineScatter(gaps);
    if (gaps.empty())
    {
        return;
    }
    // Listed walls that share a point (on any rank) meet at a corner: no
    // gap (each point's first and last listed patch: the pairs of those
    // that meet along an edge)
    const polyBoundaryMesh& pbm = mesh_.boundaryMesh();
    const label n = patchIDs_.size();
    labelList first(mesh_.nPoints(), labelMax);
    labelList last(mesh_.nPoints(), -1);
    forAll(patchIDs_, k)
    {
        for (const label pointi : pbm[patchIDs_[k]].meshPoints())
        {
            first[pointi] = min(first[pointi], k);
            last[pointi] = max(last[pointi], k);
        }
    }
    syncTools::syncPointList(mesh_, first, minEqOp<label>(), labelMax);
    syncTools::syncPointList(mesh_, last, maxEqOp<label>(), label(-1));
    labelHashSet meet;
    forAll(first, pointi)
    {
        if (last[pointi] > first[pointi])
        {
            meet.insert(first[pointi]*n + last[pointi]);
        }
    }
    Pstream::combineGather(meet, HashSetOps::plusEqOp<label, Hash<label>>());
    Pstream::combineScatter(meet);
    OStringStream which;
    scalar narrowest = GREAT;
    for (const label key : gaps.sortedToc())
    {
        if (!meet.found(key))
        {
            which<< (narrowest < GREAT ? ", " : "")
                << pbm[patchIDs_[key/n]].name() << " and "
                << pbm[patchIDs_[key % n]].name() << " " << gaps[key] << " apart";
            narrowest = min(narrowest, gaps[key]);
        }
    }
    if (narrowest == GREAT)
    {
        return;
    }
    facingWarned_ = true;
    // (half the narrowest gap rounded down to 3 significant digits, so
    // that an outerDistance copied from the message fits the gap; a half
    // that has 3 digits, as 0.5, stays itself in spite of its quotient's
    // round-off)
    const scalar unit = std::pow(10, std::floor(std::log10(0.5*narrowest)) - 2);
    const scalar half = std::floor(0.5*narrowest/unit*(1 + 1e-12))*unit;
    IOWarningInFunction(dict_)
        << "Listed walls face each other across gaps narrower than twice"
        << " outerDistance (" << 2*outerDistance_ << "): "
        << which.str().c_str() << ". Where they move against each other"
        << " (pushed, sheared or turned), the middle of such a gap moves in"
        << " part with their rigid motions, blended, rather than with the"
        << " interpolated field, and the cells between their rigid layers"
        << " take up the whole relative motion and fold early: an"
        << " outerDistance of half the narrowest gap (" << half << ") and"
        << " an innerDistance of a third of that or less, covering the"
        << " layers that must stay rigid, give those cells the most room"
        << endl;
}


void Foam::rigidLayers::rigidAtBase
(
    const pointField& points0,
    const vectorField& shift
)
{
    // The walls' transforms from their displacement when the base was
    // taken (the base's: the shift's at their points, which the step then
    // fitted them from), and the zone's rigid motion with them; the step's
    // own transforms are fitted after this
    fitMovedWalls(points0, shift);
    baseRigid_.setSize(zonePoints_.size());
    forAll(zonePoints_, i)
    {
        baseRigid_[i] = zoneRigid(i);
    }
    baseRigidValid_ = true;
}


void Foam::rigidLayers::findFixedInZone(const boundaryConstraints& bc)
{
    // Each point's patch: -1 on a listed one, else the first wall whose
    // condition fixes it that holds it on any rank (labelMax: none)
    const polyBoundaryMesh& pbm = mesh_.boundaryMesh();
    labelList patchOf(mesh_.nPoints(), labelMax);
    forAllReverse(pbm, patchi)
    {
        if (isWall(pbm[patchi]) && (patchIDs_.found(patchi) || bc.fixesPatch(patchi)))
        {
            const label k = patchIDs_.found(patchi) ? -1 : patchi;
            for (const label pointi : pbm[patchi].meshPoints())
            {
                patchOf[pointi] = min(patchOf[pointi], k);
            }
        }
    }
    syncTools::syncPointList(mesh_, patchOf, minEqOp<label>(), labelMax);

    DynamicList<label> zonei, patches;
    forAll(zonePoints_, i)
    {
        const label pointi = zonePoints_[i];
        const label patchi = patchOf[pointi];
        if
        (
            patchi >= 0 && patchi != labelMax && bc.fixed()[pointi]
        )
        {
            zonei.append(i);
            patches.append(patchi);
        }
    }
    fixedInZone_.transfer(zonei);
    fixedInZonePatch_.transfer(patches);
    fixedInZoneToWarn_ = returnReduce(fixedInZone_.size() > 0, orOp<bool>());
}


void Foam::rigidLayers::warnFixedInZone
(
    const vectorField& from0,
    const solutionFrame& frame
)
{
    // How far each such point's prescribed displacement departs from the
    // rigid motion of the layers about it (in the blend: the weight's share
    // of it), against its distance from the wall: the shear of the cells
    // between
    scalarField shear(fixedInZone_.size());
    scalar maxShear = 0;
    forAll(fixedInZone_, k)
    {
        const label i = fixedInZone_[k];
        const label pointi = zonePoints_[i];
        shear[k] =
            zoneWeight_[i]*mag(frame.inFrame(pointi, zoneRigid(i) - from0[pointi]))
           /max(mag(zoneArm_[i]), VSMALL);
        maxShear = max(maxShear, shear[k]);
    }
    // (a shear of this size is one of some 0.6 deg: below it, as where a
    // pushed side moves along a listed wall it meets, no warning)
    const scalar warnShear = 0.01;
    reduce(maxShear, maxOp<scalar>());
    if (maxShear < warnShear)
    {
        return;
    }
    fixedInZoneToWarn_ = false;

    const polyBoundaryMesh& pbm = mesh_.boundaryMesh();
    const boolList owned(ownedPoints(mesh_));
    wordHashSet names;
    label n = 0;
    scalar nearest = GREAT;
    forAll(fixedInZone_, k)
    {
        if (shear[k] >= warnShear)
        {
            const label i = fixedInZone_[k];
            names.insert(pbm[fixedInZonePatch_[k]].name());
            nearest = min(nearest, mag(zoneArm_[i]));
            n += owned[zonePoints_[i]];
        }
    }
    reduce(n, sumOp<label>());
    reduce(nearest, minOp<scalar>());
    Pstream::combineGather(names, HashSetOps::plusEqOp<word>());
    Pstream::combineScatter(names);
    IOWarningInFunction(dict_)
        << n << " points of " << flatOutput(names.sortedToc())
        << ", whose boundary conditions fix their displacement, lie"
        << " within outerDistance " << outerDistance_ << " of the walls (the"
        << " nearest " << nearest << " from them; innerDistance "
        << innerDistance_ << "): at time "
        << mesh_.time().timeName() << " that displacement departs from the"
        << " motion the layers give the points about them by up to "
        << std::round(1000*maxShear)/10 << "% of their distance from the"
        << " walls, which shears the cells between. List those patches"
        << " too, or keep the layers off them: outerDistance (and"
        << " innerDistance) less than " << nearest << endl;
}


// ************************************************************************* //
