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
#include "sumsAndMaxima.H"
#include "syncTools.H"
#include "globalMeshData.H"
#include "polyMesh.H"
#include "emptyPointPatch.H"
#include "bitSet.H"
#include "cyclicPolyPatch.H"
#include "processorPolyPatch.H"
#include "processorCyclicPolyPatch.H"
#include "unitConversion.H"

#include <algorithm>
#include <cmath>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    //- The cyclic coupling of a patch: the patch itself (a cyclic, not
    //  split over ranks), the cyclic a processorCyclic is part of, else none
    const Foam::cyclicPolyPatch* cyclicCoupling(const Foam::polyPatch& pp)
    {
        using namespace Foam;
        if (isA<processorCyclicPolyPatch>(pp))
        {
            return isA<cyclicPolyPatch>
            (
                refCast<const processorCyclicPolyPatch>(pp).referPatch()
            );
        }
        return isA<processorPolyPatch>(pp) ? nullptr : isA<cyclicPolyPatch>(pp);
    }
}


// * * * * * * * * * * * * * * * Global Functions  * * * * * * * * * * * * * //

Foam::boolList Foam::ownedPoints(const polyMesh& mesh)
{
    const globalMeshData& gd = mesh.globalData();
    const labelList& coupledPoints = gd.coupledPatch().meshPoints();
    labelList owner(coupledPoints.size(), Pstream::myProcNo());
    globalMeshData::syncData
    (
        owner,
        gd.globalCoPointSlaves(),
        labelListList(0),
        gd.globalCoPointSlavesMap(),
        minEqOp<label>()
    );
    boolList owned(mesh.nPoints(), true);
    forAll(coupledPoints, i)
    {
        owned[coupledPoints[i]] = owner[i] == Pstream::myProcNo();
    }
    return owned;
}


Foam::label Foam::nOwnedGlobal(const boolList& owned, const labelUList& points)
{
    label n = 0;
    for (const label pointi : points)
    {
        n += owned[pointi];
    }
    return returnReduce(n, sumOp<label>());
}


Foam::label Foam::nOwnedGlobal(const boolList& owned)
{
    return returnReduce
    (
        label(std::count(owned.begin(), owned.end(), true)),
        sumOp<label>()
    );
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::labelList Foam::boundaryConstraints::onAnyRank
(
    const polyMesh& mesh,
    labelList& flag
)
{
    syncTools::syncPointList(mesh, flag, maxEqOp<label>(), label(0));
    DynamicList<label> points;
    forAll(flag, pointi)
    {
        if (flag[pointi])
        {
            points.append(pointi);
        }
    }
    return labelList(std::move(points));
}


Foam::boundaryConstraints::boundaryConstraints
(
    const pointVectorField& pointDisplacement,
    const pointField& points0,
    const pointField& base,
    const scalar curvedSlipAngle,
    const vectorField* shift
)
:
    pMesh_(pointDisplacement.mesh()),
    frame_(std::make_shared<const solutionFrame>(pMesh_(), base)),
    nCyclicGlobal_(0),
    nSurfaceGlobal_(0),
    curvedSlipCos_(std::cos(degToRad(curvedSlipAngle)))
{
    const polyMesh& mesh = pMesh_();
    owned_ = ownedPoints(mesh);

    // The points of every patch but empty ones, and of those whose
    // conditions can fix or slide them (not coupled) on any rank: a
    // processor boundary can cut such a patch at its edge
    bitSet onPatch(mesh.nPoints());
    labelList onCondition(mesh.nPoints(), 0);
    for (const pointPatch& pp : pMesh_.boundary())
    {
        if (!isA<emptyPointPatch>(pp))
        {
            onPatch.set(pp.meshPoints());
            if (!pp.coupled())
            {
                UIndirectList<label>(onCondition, pp.meshPoints()) = 1;
            }
        }
    }
    // (and the points on an axisymmetric mesh's axis, which slide along it)
    onPatch.set(frame_->axisPoints());
    boundaryPoints_ = onPatch.sortedToc();
    conditionPoints_ =
        std::make_shared<const sharedPoints>(mesh, onAnyRank(mesh, onCondition));

    // The points of cyclic couplings, and their copies on other ranks
    // (through processor patches)
    labelList joined(mesh.nPoints(), 0);
    for (const polyPatch& pp : mesh.boundaryMesh())
    {
        if (cyclicCoupling(pp))
        {
            UIndirectList<label>(joined, pp.meshPoints()) = 1;
        }
    }
    cyclicPoints_ = onAnyRank(mesh, joined);
    nCyclicGlobal_ = returnReduce(cyclicPoints_.size(), sumOp<label>());

    fixingPatch_.setSize(mesh.boundaryMesh().size(), false);
    for (const pointPatchVectorField& pf : pointDisplacement.boundaryField())
    {
        fixingPatch_[pf.patch().index()] = pf.fixesValue();
    }
    findProjectingPatches(pointDisplacement);
    if (nCyclicGlobal_ > 0)
    {
        // (the patches in order: the last that fixes a point wins; over the
        // point's own copies on other ranks, never through a transform)
        labelList own(mesh.nPoints(), 0);
        for (const pointPatchVectorField& pf : pointDisplacement.boundaryField())
        {
            if (!pf.patch().coupled() && pf.type() != "empty" && pf.fixesValue())
            {
                UIndirectList<label>(own, pf.patch().meshPoints()) =
                    pf.patch().index() + 1;
            }
        }
        sharedPoints(mesh, cyclicPoints_, true)
            .combineMesh(own, maxEqOp<label>(), label(0));
        cyclicOwnFixed_ = UIndirectList<label>(own, cyclicPoints_);
    }
    findCyclicAxisPoints(base);

    readSlipPlanes(pointDisplacement, points0, base);
    update(pointDisplacement, shift);
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::boundaryConstraints::findCyclicAxisPoints(const pointField& base)
{
    const polyMesh& mesh = pMesh_();
    const scalar onAxis = 1e-9*mesh.bounds().mag();
    DynamicList<label> points;
    DynamicList<vector> axes;
    for (const polyPatch& pp : mesh.boundaryMesh())
    {
        const cyclicPolyPatch* cyc = cyclicCoupling(pp);
        if (!cyc || cyc->transform() != coupledPolyPatch::ROTATIONAL)
        {
            continue;
        }
        const vector axis = cyc->rotationAxis()/mag(cyc->rotationAxis());
        for (const label pointi : pp.meshPoints())
        {
            const vector r = base[pointi] - cyc->rotationCentre();
            if (mag(r - (r & axis)*axis) <= onAxis)
            {
                points.append(pointi);
                axes.append(axis);
            }
        }
    }
    cyclicAxisPoints_.transfer(points);
    cyclicAxes_.transfer(axes);
}


bool Foam::boundaryConstraints::heldComponents
(
    const label pointi,
    bool held[3]
) const
{
    if (fixed_[pointi])
    {
        held[0] = held[1] = held[2] = true;
        return true;
    }
    return frame_->mask(pointi, slide_[pointi], held);
}


void Foam::boundaryConstraints::collectControls()
{
    // Control points in the frame's directions
    const solutionFrame& frame = *frame_;
    const label nd = frame.size();
    DynamicList<label> ctrl, proj;
    mask_.clear();
    values_.clear();
    for (const label pointi : boundaryPoints_)
    {
        bool m[3];
        if (!heldComponents(pointi, m))
        {
            proj.append(pointi);
            continue;
        }
        bool any = false;
        for (label k = 0; k < nd; ++k)
        {
            any = any || m[k];
        }
        if (!any || !owned_[pointi])
        {
            continue;
        }
        ctrl.append(pointi);
        vector b[3];
        frame.basis(pointi, b);
        for (label k = 0; k < nd; ++k)
        {
            mask_.push_back(m[k]);
            values_.push_back(fixed_[pointi] ? (b[k] & value_[pointi]) : 0.0);
        }
    }
    controlPoints_.transfer(ctrl);
    projected_.transfer(proj);
    nControlGlobal_ = -1;
    nProjectedGlobal_ = -1;
}


void Foam::boundaryConstraints::countGlobal() const
{
    if (nControlGlobal_ < 0)
    {
        scalarList counts({scalar(controlPoints_.size()), scalar(projected_.size())});
        scalarList none;
        sumsAndMaxima(counts, none);
        nControlGlobal_ = label(counts[0]);
        nProjectedGlobal_ = label(counts[1]);
    }
}


Foam::boundaryConstraints::boundaryConstraints
(
    const boundaryConstraints& bc,
    const vectorField& displacement
)
:
    pMesh_(bc.pMesh_),
    frame_(bc.frame_),
    fixed_(bc.fixed_),
    value_(bc.value_),
    slide_(bc.slide_),
    conditionPoints_(bc.conditionPoints_),
    owned_(bc.owned_),
    boundaryPoints_(bc.boundaryPoints_),
    cyclicPoints_(bc.cyclicPoints_),
    nCyclicGlobal_(bc.nCyclicGlobal_),
    fixingPatch_(bc.fixingPatch_),
    nSurfaceGlobal_(0),
    onSurface_(bc.onSurface_),
    projectedByCondition_(bc.projectedByCondition_),
    curvedSlipCos_(bc.curvedSlipCos_)
{
    for (const label pointi : bc.projected_)
    {
        fixed_[pointi] = true;
        value_[pointi] = displacement[pointi];
    }
    const auto fixUnfixed = [&](const label pointi)
    {
        if (!bc.fixed_[pointi])
        {
            fixed_[pointi] = true;
            value_[pointi] = displacement[pointi];
        }
    };
    for (const label pointi : bc.cyclicPoints_)
    {
        fixUnfixed(pointi);
    }
    for (const label pointi : bc.onSurface_)
    {
        fixUnfixed(pointi);
    }
    collectControls();
}


void Foam::boundaryConstraints::checkCouplings
(
    const pointVectorField& pointDisplacement,
    const pointField& points0,
    const word& solver
)
{
    // (cyclicAMI says it is not coupled(): the class tells)
    const polyBoundaryMesh& pbm = pointDisplacement.mesh()().boundaryMesh();
    forAll(pbm, patchi)
    {
        const polyPatch& pp = pbm[patchi];
        if
        (
            isA<coupledPolyPatch>(pp)
         && !isA<processorPolyPatch>(pp)
         && !isA<cyclicPolyPatch>(pp)
         && !pointDisplacement.boundaryField()[patchi].fixesValue()
        )
        {
            FatalErrorInFunction
                << "Patch " << pp.name() << " is a " << pp.type()
                << " coupling, which " << solver << " does not interpolate:"
                << " its two sides would move apart. Supported couplings:"
                << " cyclic (translational or rotational) and processor"
                << " patches; a " << pp.type() << " whose sides'"
                << " pointDisplacement conditions prescribe their motion"
                << " (patchType " << pp.type() << "; type fixedValue; ...)"
                << " is accepted. The mesh is not moved" << exit(FatalError);
        }
    }
    warnSplitBaffles(pbm.mesh(), points0);
}


void Foam::boundaryConstraints::matchCyclic(vectorField& displacement) const
{
    if (nCyclicGlobal_ == 0)
    {
        return;
    }
    // Sums and counts over each set of joined points (syncPointList adds
    // them, each transformed to the receiving point's side), of the free
    // points and of the fixed ones: fixed points keep their values, and
    // where a set has some, its free points take their mean (a rigid
    // zone's outermost point on one side of a pair, fixed at the zone's
    // motion, carries its partner along), else the free points' mean
    const polyMesh& mesh = pMesh_();
    if (cyclicSum_.size() != mesh.nPoints())
    {
        // (zero at the points of processor patches too: syncPointList
        // combines every coupled point)
        cyclicSum_.setSize(mesh.nPoints(), Zero);
        cyclicCount_.setSize(mesh.nPoints(), 0);
        cyclicFixedSum_.setSize(mesh.nPoints(), Zero);
        cyclicFixedCount_.setSize(mesh.nPoints(), 0);
    }
    // (each point counted once: on the rank that owns it, not on those
    // that hold a copy of it through a processor patch)
    for (const label pointi : cyclicPoints_)
    {
        const bool counted = owned_[pointi];
        const bool free = !fixed_[pointi];
        cyclicSum_[pointi] = counted && free ? displacement[pointi] : Zero;
        cyclicCount_[pointi] = counted && free;
        cyclicFixedSum_[pointi] = counted && !free ? value_[pointi] : Zero;
        cyclicFixedCount_[pointi] = counted && !free;
    }
    syncTools::syncPointList(mesh, cyclicSum_, plusEqOp<vector>(), vector::zero);
    syncTools::syncPointList(mesh, cyclicCount_, plusEqOp<scalar>(), scalar(0));
    syncTools::syncPointList(mesh, cyclicFixedSum_, plusEqOp<vector>(), vector::zero);
    syncTools::syncPointList(mesh, cyclicFixedCount_, plusEqOp<scalar>(), scalar(0));
    for (const label pointi : cyclicPoints_)
    {
        if (fixed_[pointi])
        {
            continue;
        }
        if (cyclicFixedCount_[pointi] > 0)
        {
            displacement[pointi] = cyclicFixedSum_[pointi]/cyclicFixedCount_[pointi];
        }
        else if (cyclicCount_[pointi] > 0)
        {
            displacement[pointi] = cyclicSum_[pointi]/cyclicCount_[pointi];
        }
    }
    // (a point's copies on several ranks: sums added in different orders
    // may differ in the last bit; every copy takes the same one)
    if (Pstream::parRun())
    {
        for (const label pointi : cyclicPoints_)
        {
            cyclicSum_[pointi] = displacement[pointi];
        }
        syncTools::syncPointList(mesh, cyclicSum_, maxMagSqrEqOp<vector>(), vector::zero);
        for (const label pointi : cyclicPoints_)
        {
            if (!fixed_[pointi]) displacement[pointi] = cyclicSum_[pointi];
        }
    }
}


void Foam::boundaryConstraints::addPoints(const labelList& points)
{
    bitSet all(pMesh_().nPoints());
    all.set(boundaryPoints_);
    all.set(points);
    if (label(all.count()) != boundaryPoints_.size())
    {
        boundaryPoints_ = all.sortedToc();
    }
    added_.resize(pMesh_().nPoints());
    added_.set(points);
}


std::vector<std::uint8_t> Foam::boundaryConstraints::addedControls() const
{
    std::vector<std::uint8_t> added(controlPoints_.size(), 0);
    forAll(controlPoints_, i)
    {
        added[i] = added_.test(controlPoints_[i]);
    }
    return added;
}


void Foam::boundaryConstraints::fix(const label pointi, const vector& value)
{
    fixedSync_[pointi] = 1;
    fixed_[pointi] = true;
    value_[pointi] = value;
}


void Foam::boundaryConstraints::slide(const label pointi, const pointConstraint& pc)
{
    slide_[pointi] = pc;
}


Foam::label Foam::boundaryConstraints::nControlGlobal() const
{
    countGlobal();
    return nControlGlobal_;
}


Foam::label Foam::boundaryConstraints::nRefitGlobal() const
{
    countGlobal();
    return nProjectedGlobal_ + nCyclicGlobal_ + nSurfaceGlobal_;
}


void Foam::boundaryConstraints::constrain(vectorField& displacement) const
{
    const solutionFrame& frame = *frame_;
    for (const label pointi : boundaryPoints_)
    {
        vector& d = displacement[pointi];
        if (fixed_[pointi])
        {
            d = value_[pointi];
        }
        else if (onSurface_.test(pointi))
        {
            // (their conditions project them: onto the surface, not the
            // planes they slid on in the first fit)
        }
        else if (slide_[pointi].first() > 0)
        {
            slideOne(frame, pointi, d);
        }
    }
    if (frame_->size() < 3)
    {
        frame_->constrain(displacement);
    }
}


void Foam::boundaryConstraints::slideOne
(
    const solutionFrame& frame,
    const label pointi,
    vector& d
) const
{
    // (a constraint along the frame's directions removes exactly those
    // components: along an axis, exactly zero)
    bool m[3];
    if (frame.mask(pointi, slide_[pointi], m))
    {
        vector b[3];
        frame.basis(pointi, b);
        for (label k = 0; k < frame.size(); ++k)
        {
            if (m[k]) d -= (b[k] & d)*b[k];
        }
    }
    else
    {
        d = slide_[pointi].constrainDisplacement(d);
    }
}


std::vector<std::uint8_t> Foam::boundaryConstraints::interpolatedComponents
(
    const labelUList& points
) const
{
    // (the components constrain() sets and collectControls() makes control
    // values)
    const label nd = frame_->size();
    std::vector<std::uint8_t> read(nd*points.size(), 1);
    if (frame_->axisymmetric())
    {
        return read;
    }
    forAll(points, i)
    {
        bool m[3];
        if (heldComponents(points[i], m))
        {
            for (label k = 0; k < nd; ++k)
            {
                read[i*nd + k] = !m[k];
            }
        }
    }
    return read;
}


bool Foam::boundaryConstraints::sameControls
(
    const labelList& points,
    const std::vector<std::uint8_t>& mask
) const
{
    return controlPoints_ == points && mask_ == mask;
}


// ************************************************************************* //
