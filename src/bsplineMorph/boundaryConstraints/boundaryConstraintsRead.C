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

Description
    boundaryConstraints: what the patches' conditions prescribe, read at
    every step (update()): fixed values, sliding planes, and the checks of
    what they prescribe (non-finite values, components across an empty or
    wedge frame).

\*---------------------------------------------------------------------------*/

#include "boundaryConstraints.H"
#include "sumsAndMaxima.H"
#include "valuePointPatchFields.H"
#include "facePointPatch.H"
#include "emptyPointPatch.H"
#include "OStringStream.H"
#include "HashOps.H"
#include "hugePageLists.H"

#include <cmath>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    //- The names in set on any rank, sorted (collective)
    Foam::wordList allNames(Foam::wordHashSet& set)
    {
        using namespace Foam;
        Pstream::combineGather(set, HashSetOps::plusEqOp<word>());
        Pstream::combineScatter(set);
        return set.sortedToc();
    }

    //- The names in set on any rank not yet in warned, sorted, then added
    //  to it (collective)
    Foam::wordList toWarnOf(Foam::wordHashSet& set, Foam::wordHashSet& warned)
    {
        allNames(set);
        set -= warned;
        warned += set;
        return set.sortedToc();
    }

    //- toWarnOf, gathered only when a rank has a name; most: the largest
    //  of every rank's (collective)
    Foam::wordList toWarnOf
    (
        Foam::wordHashSet& set,
        Foam::scalar& most,
        Foam::wordHashSet& warned
    )
    {
        using namespace Foam;
        scalarList none;
        scalarList any({scalar(set.size()), most});
        sumsAndMaxima(none, any);
        most = any[1];
        return any[0] > 0 ? toWarnOf(set, warned) : wordList();
    }

    //- Whether d, a prescribed displacement's part or two such values'
    //  difference, is worth a warning: from 1e-10 of the mesh's size
    //  (meshSize) and 1e-6 of the value on; below either it is the frame's
    //  own precision (solidBodyMotionDisplacement's rotation about the empty
    //  axis leaves round-off there; the wedge planes of OpenFOAM's
    //  movingCone, its vertices given to 8 digits, meet in an axis 7e-9 rad
    //  off x)
    bool beyondRoundOff
    (
        const Foam::scalar d,
        const Foam::scalar value,
        const Foam::scalar meshSize
    )
    {
        return d > 1e-10*meshSize && d > 1e-6*value;
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::boundaryConstraints::resetPointArrays()
{
    // The per-point arrays keep their storage from step to step (no new
    // pages for the mesh-sized arrays at every step)
    const label nPoints = pMesh_().nPoints();
    labelList& fixed = fixedSync_;
    if (fixed.size() != nPoints)
    {
        // (read and reset at the boundary points every step: on huge pages)
        setSizeOnHugePages(fixed, nPoints);
        fixed = 0;
        setSizeOnHugePages(fixed_, nPoints);
        fixed_ = false;
        setSizeOnHugePages(value_, nPoints);
        value_ = Zero;
        setSizeOnHugePages(slide_, nPoints);
        slide_ = pointConstraint();
        onHugePages(fixed);
        onHugePages(fixed_);
        onHugePages(value_);
        onHugePages(slide_);
    }
    // (only what the last update set is reset: storing a pointConstraint at
    // every boundary point cost more than the rest of the update together)
    for (const label pointi : boundaryPoints_)
    {
        if (fixed[pointi])
        {
            fixed[pointi] = 0;
            value_[pointi] = Zero;
        }
        if (slide_[pointi].first())
        {
            slide_[pointi] = pointConstraint();
        }
    }
}


void Foam::boundaryConstraints::readFixedPatch
(
    const pointPatchVectorField& pf,
    const vectorField& disp,
    wordHashSet& nonFinite,
    wordHashSet& emptyDirection
)
{
    const pointPatch& pp = pf.patch();
    const labelList& meshPoints = pp.meshPoints();
    const solutionFrame& frame = *frame_;
    // The condition's own values (the internal field at a point on a fixed
    // and a slip patch depends on their evaluation order)
    const valuePointPatchVectorField* vpf = isA<valuePointPatchVectorField>(pf);
    const vectorField values
    (
        vpf
      ? static_cast<const vectorField&>(*vpf)
      : vectorField(disp, meshPoints)
    );
    // A component out of the frame is worth a warning beyond round-off
    const bool twoD = frame.size() < 3;
    const scalar meshSize = pMesh_().bounds().mag();
    // Values over 1e8 times the mesh's size are no mesh motion (the points
    // would keep a few digits of their cells; near 1e150 their squares
    // overflow): refused with the non-finite ones
    const scalar huge = 1e8*meshSize;
    forAll(meshPoints, i)
    {
        const label pointi = meshPoints[i];
        // (the patches in order: a point of several takes the last one's
        // value, and its index, with which update() decides on every rank)
        fixedSync_[pointi] = pp.index() + 1;
        value_[pointi] = values[i];
        for (direction c = 0; c < 3; ++c)
        {
            if (!std::isfinite(values[i][c]) || mag(values[i][c]) > huge)
            {
                nonFinite.insert(pp.name());
            }
        }
        // (an axisymmetric mesh's front and back points: by pairs, after
        // the sync, in meanFrontBack)
        if (twoD && !frame.paired(pointi))
        {
            const scalar across =
                mag(values[i] - frame.inFrame(pointi, values[i]));
            if (beyondRoundOff(across, mag(values[i]), meshSize))
            {
                emptyDirection.insert(pp.name());
            }
        }
    }
}


void Foam::boundaryConstraints::readSlidingPatch(const pointPatchVectorField& pf)
{
    const pointPatch& pp = pf.patch();
    const labelList& meshPoints = pp.meshPoints();
    const solutionFrame& frame = *frame_;
    if (frame.axisymmetric() && pp.constraintType() == "wedge")
    {
        // The frame keeps every point in its meridian plane
        return;
    }
    // A plane's normal as the frame sees it at a point (zero: the plane
    // holds nothing in the frame)
    auto applyNormal = [&](const label pointi, const vector& n)
    {
        const vector m = frame.planeNormal(pointi, n);
        if (m != vector::zero)
        {
            slide_[pointi].applyConstraint(m);
        }
    };
    if (slidesOnFaces(pf))
    {
        // Each face's own normal on each of its points, combined (plane,
        // line, fixed): a patch spanning several planes (the faces of a box)
        // constrains its edge points to the line where they meet. Averaged
        // point normals would not: they tilt at edges and differ between the
        // ranks that share a point. Where the patch is smooth (a curved wall,
        // or a flat one), the mean of its faces' normals at the point, summed
        // over the ranks that hold it: the point slides in that plane, as
        // OpenFOAM's slip slides along point normals (leaving a wall of
        // radius R by about d^2/2R for a slide d)
        const polyPatch& patch = refCast<const facePointPatch>(pp).patch();
        const vectorField& nf = slipNormals_[pp.index()];
        const labelListList& pointFaces = patch.pointFaces();
        const vectorField& mean = slipMean_[pp.index()];
        forAll(pointFaces, lp)
        {
            if (mean[lp] != vector::zero)
            {
                applyNormal(meshPoints[lp], mean[lp]);
                continue;
            }
            for (const label facei : pointFaces[lp])
            {
                applyNormal(meshPoints[lp], nf[facei]);
            }
        }
    }
    else if (pf.type() == "fixedNormalSlip")
    {
        // The normal is private to the condition: read it back from its output
        OStringStream os;
        pf.write(os);
        const dictionary d(IStringStream(os.str())());
        vector n = d.get<vector>("n");
        n /= mag(n) + VSMALL;
        for (const label pointi : meshPoints)
        {
            applyNormal(pointi, n);
        }
    }
    else if (pp.constraintType() != word::null)
    {
        // symmetryPlane, wedge, cyclicSlip: the patch's own constraint
        forAll(meshPoints, i)
        {
            // (a plane: its normal as the frame sees it, as the slip
            // patches' above)
            pointConstraint pc;
            pp.applyConstraint(i, pc);
            if (pc.first() == 1)
            {
                applyNormal(meshPoints[i], pc.second());
            }
            else
            {
                slide_[meshPoints[i]].combine(pc);
            }
        }
    }
}


bool Foam::boundaryConstraints::slidesOnFaces(const pointPatchVectorField& pf)
{
    return
        !pf.patch().coupled() && !pf.fixesValue()
     && (
            pf.type() == "slip" || pf.patch().constraintType() == "symmetry"
         || projectsOntoSurface(pf)
        );
}


void Foam::boundaryConstraints::readSlipPlanes
(
    const pointVectorField& pointDisplacement,
    const pointField& points0,
    const pointField& base
)
{
    const label nPatches = pointDisplacement.boundaryField().size();
    slipNormals_.setSize(nPatches);
    slipMean_.setSize(nPatches);
    for (const pointPatchVectorField& pf : pointDisplacement.boundaryField())
    {
        if (!slidesOnFaces(pf))
        {
            continue;
        }
        const polyPatch& patch = refCast<const facePointPatch>(pf.patch()).patch();
        const auto unitNormals = [&patch](const pointField& points)
        {
            vectorField nf(patch.size());
            forAll(patch, facei)
            {
                nf[facei] = patch[facei].unitNormal(points);
            }
            return nf;
        };
        vectorField& nf0 = slipNormals_[pf.patch().index()];
        nf0 = unitNormals(points0);
        // (a rebased morph's curved walls slide in the planes at its base)
        slipMean_[pf.patch().index()] =
            &base == &points0
          ? curvedSlip(patch, nf0, nf0)
          : curvedSlip(patch, nf0, unitNormals(base));
    }
}


void Foam::boundaryConstraints::sumFaceNormals
(
    const polyPatch& patch,
    const sharedPoints& shared,
    const vectorField& nf,
    List<vector>& sum,
    List<scalar>& count
) const
{
    const labelListList& pointFaces = patch.pointFaces();
    sum = List<vector>(patch.nPoints(), Zero);
    count = List<scalar>(patch.nPoints(), Zero);
    forAll(pointFaces, lp)
    {
        for (const label facei : pointFaces[lp])
        {
            sum[lp] += nf[facei];
            count[lp] += 1;
        }
    }
    shared.sum(sum);
    shared.sum(count);
}


Foam::vectorField Foam::boundaryConstraints::curvedSlip
(
    const polyPatch& patch,
    const vectorField& nf0,
    const vectorField& nf
) const
{
    List<vector> sum;
    List<scalar> count;
    const sharedPoints shared(pMesh_(), patch.meshPoints());
    sumFaceNormals(patch, shared, nf0, sum, count);
    // Smooth: |sum| of unit normals at least cos curvedSlipAngle of their
    // count (two faces: within twice the angle of each other). Bent: not
    // coplanar to rounding, 1e-9: those slide in the base's mean plane (a
    // rebased morph's curved wall), the coplanar ones in points0's, which
    // stays put (a wall a little off flat, snapped: each face's own plane
    // would leave the point on the first face's of a rank, which differs
    // between decompositions)
    const scalar smooth = curvedSlipCos_;
    vectorField mean(patch.nPoints(), Zero);
    boolList bentAt(patch.nPoints(), false);
    bool bent = false;
    forAll(sum, lp)
    {
        const scalar m = mag(sum[lp]);
        if (m >= smooth*count[lp])
        {
            mean[lp] = sum[lp]/m;
            bentAt[lp] = m < (1 - 1e-9)*count[lp];
            bent = bent || bentAt[lp];
        }
    }
    reduce(bent, orOp<bool>());
    if (bent && &nf != &nf0)
    {
        sumFaceNormals(patch, shared, nf, sum, count);
        forAll(sum, lp)
        {
            if (bentAt[lp])
            {
                mean[lp] = sum[lp]/mag(sum[lp]);
            }
        }
    }
    return mean;
}


void Foam::boundaryConstraints::checkPrescribed
(
    wordHashSet& nonFinite,
    wordHashSet& emptyDirection
)
{
    const polyMesh& mesh = pMesh_();

    // Whether any rank has either kind of value, in one reduction; the
    // patches' names are gathered only then
    scalarList none;
    scalarList any({scalar(nonFinite.size()), scalar(emptyDirection.size())});
    sumsAndMaxima(none, any);

    // Non-finite values stop everything here, on every rank, before they
    // reach any arithmetic (with FOAM_SIGFPE a NaN comparison traps)
    if (any[0] > 0)
    {
        FatalErrorInFunction
            << "pointDisplacement has non-finite (NaN or Inf) or huge (over 1e8"
            << " times the mesh's bounding-box diagonal) values on patches "
            << flatOutput(allNames(nonFinite)) << " at time "
            << mesh.time().timeName() << "; the mesh is not moved"
            << exit(FatalError);
    }

    // A 2D case moves in its plane: a prescribed component out of it is
    // dropped, with a warning (once per patch; a 3D case has none, on any
    // rank)
    if (any[1] == 0)
    {
        return;
    }
    warnAcrossFrame(toWarnOf(emptyDirection, warnedEmptyDirection_));
}


void Foam::boundaryConstraints::warnAcrossFrame(const wordList& patches) const
{
    if (patches.size())
    {
        const polyMesh& mesh = pMesh_();
        OStringStream names;
        for (const word& name : patches)
        {
            names<< ' ' << name;
        }
        const bool axisymmetric = frame_->axisymmetric();
        WarningInFunction
            << "pointDisplacement prescribes a non-zero displacement"
            << (
                   axisymmetric
                 ? " across the meridian planes (around the axis) of this"
                   " axisymmetric (wedge) case"
                 : " in the empty direction of this 2D case"
               )
            << " on patches:" << names.str().c_str() << ", at time "
            << mesh.time().timeName() << ": that component is dropped (the"
            << " mesh moves "
            << (axisymmetric ? "along its axis and radii" : "in its plane")
            << " only)" << endl;
    }
}


void Foam::boundaryConstraints::meanFrontBack()
{
    // (after the sync: a pair's values, and so their mean, are the same on
    // every rank that holds it; a difference is worth a warning beyond
    // round-off). Across the meridian
    // planes, the mirror part of the pair's values (opposite components:
    // a radial motion given as one Cartesian vector) is no motion around
    // the axis; the mean is, and is warned about
    const solutionFrame& frame = *frame_;
    const scalar meshSize = pMesh_().bounds().mag();
    const polyBoundaryMesh& patches = pMesh_().boundaryMesh();
    wordHashSet differ, around;
    scalar most = 0;
    for (const labelPair& pq : frame.meridianPairs())
    {
        const label p = pq.first();
        const label q = pq.second();
        if (!fixedSync_[p] || !fixedSync_[q])
        {
            continue;
        }
        vector bp[3], bq[3];
        frame.basis(p, bp);
        frame.basis(q, bq);
        const scalar scale = max(mag(value_[p]), mag(value_[q]));
        const scalar swirl =
            0.5*mag((value_[p] & (bp[0] ^ bp[1])) + (value_[q] & (bq[0] ^ bq[1])));
        if (beyondRoundOff(swirl, scale, meshSize))
        {
            around.insert(patches[fixedSync_[p] - 1].name());
            around.insert(patches[fixedSync_[q] - 1].name());
        }
        for (label k = 0; k < frame.size(); ++k)
        {
            const scalar vp = bp[k] & value_[p];
            const scalar vq = bq[k] & value_[q];
            const scalar mean = 0.5*(vp + vq);
            value_[p] += (mean - vp)*bp[k];
            value_[q] += (mean - vq)*bq[k];
            const scalar d = mag(vp - vq);
            if (beyondRoundOff(d, scale, meshSize))
            {
                differ.insert(patches[fixedSync_[p] - 1].name());
                differ.insert(patches[fixedSync_[q] - 1].name());
                most = max(most, d);
            }
        }
    }

    scalar largest = 0;
    warnAcrossFrame(toWarnOf(around, largest, warnedEmptyDirection_));
    const wordList names(toWarnOf(differ, most, warnedFrontBack_));
    if (names.size())
    {
        WarningInFunction
            << "pointDisplacement prescribes different displacements to the"
            << " front and back points of this axisymmetric (wedge) case on"
            << " patches " << flatOutput(names) << " (up to "
            << most << " apart along the axis or radius), at time "
            << pMesh_().time().timeName() << ": a motion that is not"
            << " axisymmetric (e.g. a tilt across the axis). Both points of"
            << " each pair take the mean of their values" << endl;
    }
}


void Foam::boundaryConstraints::warnCyclicConflicts
(
    const labelUList& ownFixed,
    const UList<vector>& ownValue
)
{
    // (after the syncs: a point whose index rose above its own patches'
    // took a later patch's at a partner, its value through the transform;
    // one whose partner is of the same patch took the larger of the two)
    const scalar meshSize = pMesh_().bounds().mag();
    const polyBoundaryMesh& patches = pMesh_().boundaryMesh();
    wordHashSet overruled;
    scalar most = 0;
    forAll(ownFixed, j)
    {
        const label i = ownFixed[j];
        const label pointi = cyclicPoints_[i];
        const scalar d = mag(value_[pointi] - ownValue[j]);
        if (beyondRoundOff(d, max(mag(value_[pointi]), mag(ownValue[j])), meshSize))
        {
            const word& own = patches[cyclicOwnFixed_[i] - 1].name();
            overruled.insert
            (
                fixedSync_[pointi] > cyclicOwnFixed_[i]
              ? own + " by " + patches[fixedSync_[pointi] - 1].name()
              : own + " by itself across the coupling"
            );
            most = max(most, d);
        }
    }

    const wordList pairs(toWarnOf(overruled, most, warnedCyclicConflicts_));
    if (pairs.size())
    {
        OStringStream names;
        forAll(pairs, k)
        {
            names<< (k ? ", " : "") << pairs[k].c_str();
        }
        WarningInFunction
            << "pointDisplacement prescribes different displacements to points"
            << " that cyclic couplings join (up to " << most << " apart), at"
            << " time " << pMesh_().time().timeName() << ": patches overruled: "
            << names.str().c_str() << ". Each joined set takes the value of"
            << " the last of its patches in the boundary's order (of one"
            << " patch: the larger value); the cells"
            << " beside the overruled points may fold. Prescribe the coupled"
            << " sides alike" << endl;
    }
}


void Foam::boundaryConstraints::update
(
    const pointVectorField& pointDisplacement,
    const vectorField* shift
)
{
    resetPointArrays();
    wordHashSet nonFinite;
    wordHashSet emptyDirection;
    for (const pointPatchVectorField& pf : pointDisplacement.boundaryField())
    {
        if (pf.patch().coupled() || pf.type() == "empty")
        {
            continue;
        }
        if (pf.fixesValue())
        {
            readFixedPatch
            (
                pf, pointDisplacement.primitiveField(), nonFinite, emptyDirection
            );
        }
        else
        {
            readSlidingPatch(pf);
        }
    }
    checkPrescribed(nonFinite, emptyDirection);

    // The points on an axisymmetric mesh's axis slide along it
    if (frame_->axisymmetric())
    {
        const pointConstraint alongAxis
        (
            Tuple2<label, vector>(2, frame_->axis())
        );
        for (const label pointi : frame_->axisPoints())
        {
            slide_[pointi].combine(alongAxis);
        }
    }
    // and those on a rotational cyclic pair's axis, each its own partner,
    // along that axis
    forAll(cyclicAxisPoints_, i)
    {
        slide_[cyclicAxisPoints_[i]].combine
        (
            pointConstraint(Tuple2<label, vector>(2, cyclicAxes_[i]))
        );
    }

    // A cyclic point its own patch fixes here: its value, to tell whether a
    // later patch at its partner overrules it with another
    DynamicList<label> ownFixed;
    DynamicList<vector> ownValue;
    forAll(cyclicOwnFixed_, i)
    {
        const label pointi = cyclicPoints_[i];
        if (cyclicOwnFixed_[i] && fixedSync_[pointi] == cyclicOwnFixed_[i])
        {
            ownFixed.append(i);
            ownValue.append(value_[pointi]);
        }
    }

    // The same view of every processor-shared point on all its ranks (the
    // conditions set values at their patches' points only). A point of
    // several fixed patches takes the last one's value (in the patches'
    // order, as when one rank holds them all) whichever ranks hold which;
    // so do a cyclic pair's points, through its transform
    const labelList mine(UIndirectList<label>(fixedSync_, boundaryPoints_));
    conditionPoints_->combineMesh(fixedSync_, maxEqOp<label>(), label(0));
    forAll(boundaryPoints_, i)
    {
        if (mine[i] != fixedSync_[boundaryPoints_[i]])
        {
            value_[boundaryPoints_[i]] = Zero;
        }
    }
    conditionPoints_->combineMesh(value_, maxMagSqrEqOp<vector>(), vector::zero);
    conditionPoints_->combineMesh(slide_, combineConstraintsEqOp(), pointConstraint());
    if (nCyclicGlobal_ > 0)
    {
        warnCyclicConflicts(ownFixed, ownValue);
    }
    if (frame_->axisymmetric())
    {
        meanFrontBack();
    }

    for (const label pointi : boundaryPoints_)
    {
        fixed_[pointi] = fixedSync_[pointi] != 0;
        if (shift && fixed_[pointi])
        {
            value_[pointi] -= (*shift)[pointi];
        }
    }
    collectControls();
}


// ************************************************************************* //
