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
#include "coeffsInput.H"
#include "boundaryConstraints.H"
#include "bitSet.H"
#include "HashOps.H"
#include "wordRes.H"

#include <algorithm>
#include <cmath>

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

const Foam::label Foam::rigidLayers::maxSmooth;
const Foam::scalar Foam::rigidLayers::powerTolerance = 1e-12;


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::rigidLayers::rigidLayers(const polyMesh& mesh, const dictionary& dict)
:
    mesh_(mesh),
    dict_(dict),
    innerDistance_(0),
    outerDistance_(0),
    planned_(false),
    nSmooth_(0),
    anySurfaceShell_(false),
    anyPair_(false),
    facingWarned_(false),
    fixedInZoneToWarn_(false),
    transformsFinal_(false),
    baseRigidValid_(false)
{
    // (a misspelt keyword named before a required one is found missing)
    coeffsInput::warnUnknown(dict, {"patches", "innerDistance", "outerDistance"});

    // Patches: every pattern must match a patch that can carry layers
    const wordRes patterns(dict.get<wordRes>("patches"));
    const polyBoundaryMesh& pbm = mesh.boundaryMesh();
    DynamicList<word> valid;
    forAll(pbm, patchi)
    {
        if (isWall(pbm[patchi]))
        {
            valid.append(pbm[patchi].name());
        }
    }
    if (patterns.empty())
    {
        FatalIOErrorInFunction(dict)
            << "patches: the list is empty; name the walls whose layers move"
            << " with them (valid patches: " << flatOutput(valid)
            << ", and groups of them), or remove rigidLayers"
            << exit(FatalIOError);
    }
    const HashTable<labelList>& groups = pbm.groupPatchIDs();
    labelHashSet ids;
    for (const wordRe& pattern : patterns)
    {
        // Patches by name, and the patches of the groups it names
        bool found = false;
        forAll(pbm, patchi)
        {
            const polyPatch& pp = pbm[patchi];
            bool match = pattern.match(pp.name());
            for (const word& group : pp.inGroups())
            {
                match = match || (groups.found(group) && pattern.match(group));
            }
            if (match && isWall(pp))
            {
                ids.insert(patchi);
                found = true;
            }
        }
        if (!found)
        {
            FatalIOErrorInFunction(dict)
                << "patches: " << pattern << " matches no patch that can carry"
                << " rigid layers (coupled, empty and wedge patches cannot);"
                << " valid patches: "
                << flatOutput(valid) << ", and groups of them" << exit(FatalIOError);
        }
    }
    patchIDs_ = ids.sortedToc();

    innerDistance_ = coeffsInput::getRequiredInRange<scalar>(dict, "innerDistance", 0);
    outerDistance_ = coeffsInput::getRequiredInRange<scalar>(dict, "outerDistance", 0);
    if (!(outerDistance_ > innerDistance_))
    {
        FatalIOErrorInFunction(dict)
            << coeffsInput::inputMessage([&](Ostream& os)
               {
                   os  << "outerDistance " << outerDistance_ << " must be larger"
                       << " than innerDistance " << innerDistance_ << " (the blend"
                       << " lies between them)";
               }).c_str()
            << exit(FatalIOError);
    }
}


// * * * * * * * * * * * * * * * * Selectors * * * * * * * * * * * * * * * * //

Foam::autoPtr<Foam::rigidLayers> Foam::rigidLayers::New
(
    const polyMesh& mesh,
    const dictionary& coeffDict
)
{
    if (!coeffDict.found("rigidLayers"))
    {
        return nullptr;
    }
    coeffsInput::checkDict
    (
        coeffDict, "rigidLayers",
        "patches (...); innerDistance ...; outerDistance ...;"
    );
    return autoPtr<rigidLayers>::New(mesh, coeffDict.subDict("rigidLayers"));
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::rigidLayers::checkConstrained(const boundaryConstraints& bc) const
{
    const polyBoundaryMesh& pbm = mesh_.boundaryMesh();
    wordHashSet loose;
    for (const label patchi : patchIDs_)
    {
        for (const label pointi : pbm[patchi].meshPoints())
        {
            if (!bc.constrains(pointi))
            {
                loose.insert(pbm[patchi].name());
                break;
            }
        }
    }
    Pstream::combineGather(loose, HashSetOps::plusEqOp<word>());
    Pstream::combineScatter(loose);
    if (loose.size())
    {
        FatalIOErrorInFunction(dict_)
            << "patches: the boundary conditions of pointDisplacement neither"
            << " fix nor slide the points of " << flatOutput(loose.sortedToc())
            << "; rigid layers follow walls whose motion is prescribed"
            << " (fixedValue, uniformFixedValue, solidBodyMotionDisplacement,"
            << " ...) or that slide (slip, symmetryPlane, ...)"
            << exit(FatalIOError);
    }
}


Foam::vector Foam::rigidLayers::rigidMotion
(
    const label j,
    const vector& arm
) const
{
    const scalar aSqr = magSqr(arm);
    if (aSqr <= sqr(innerDistance_))
    {
        return footDisplacement_[j] + (rotation_[j] & arm) - arm;
    }
    // Beyond innerDistance the wall's rotation as a whole (its patch's)
    // carries on along the arm; the foot's own turn against it acts on the
    // arm up to innerDistance only, so that the local turns of a deforming
    // wall (under a crease) do not fan out further
    const tensor& Rp = patchRotation_[footPatch_[j]];
    const vector inner = arm*(innerDistance_/std::sqrt(aSqr));
    return footDisplacement_[j] + (Rp & arm) - arm + ((rotation_[j] - Rp) & inner);
}


void Foam::rigidLayers::addControls
(
    boundaryConstraints& bc,
    const pointField& points0,
    const vectorField* shift
)
{
    if (!planned_)
    {
        plan(points0, bc);
        findFixedInZone(bc);
    }
    // The points of sliding listed walls within innerDistance of another
    // listed wall (below: they keep to its layers), and among them this
    // rank's wall points on one plane: they turn with the other wall's foot
    // (turnWithPairs())
    DynamicList<label> pairSliding;
    {
        const boolList& fixed = bc.fixed();
        const List<pointConstraint>& slides = bc.slides();
        DynamicList<label> pairWall;
        DynamicList<vector> normals;
        forAll(zonePair_, i)
        {
            const label pointi = zonePoints_[i];
            if
            (
                zonePair_[i] < 0 || magSqr(zoneArm_[i]) > 0 || fixed[pointi]
             || slides[pointi].first() == 0 || !pairFollows_.test(zonePair_[i])
            )
            {
                continue;
            }
            pairSliding.append(i);
            const label wi = zoneFoot_[i];
            if
            (
                slides[pointi].first() == 1 && wi < wallPoints_.size()
             && wallPoints_[wi] == pointi
            )
            {
                pairWall.append(i);
                normals.append(normalised(slides[pointi].second()));
            }
        }
        pairWall_.transfer(pairWall);
        pairWallNormal_.transfer(normals);
    }
    if (shift && !baseRigidValid_)
    {
        rigidAtBase(points0, *shift);
    }
    bc.addPoints(shellPoints_);

    // The feet's rigid motions from the prescribed wall displacements alone
    // (the sliding ones are known only after the fit)
    const boolList& fixed = bc.fixed();
    // (the walls' displacement from points0: a rebased morph's values are
    // from its base)
    const tmp<vectorField> tprescribed
    (
        shift ? tmp<vectorField>(bc.prescribed() + *shift) : tmp<vectorField>(bc.prescribed())
    );
    const vectorField& prescribed = tprescribed();
    fitRotations(points0, prescribed, &fixed);
    // Walls all of whose points are prescribed (in 3D: in 2D the part of a
    // prescribed value across the frame is dropped later) have these transforms
    // after the fit too: apply() keeps them
    bool allFixed = bc.frame().size() == 3;
    for (const label pointi : wallPoints_)
    {
        allFixed = allFixed && fixed[pointi];
    }
    transformsFinal_ = returnReduce(allFixed, andOp<bool>());
    footDisplacement_ = vectorField(prescribed, wallPoints_);
    labelList footFixed(wallPoints_.size());
    labelList footOnSurface(wallPoints_.size());
    List<pointConstraint> footSlide(wallPoints_.size());
    forAll(wallPoints_, i)
    {
        footFixed[i] = fixed[wallPoints_[i]];
        // (by their conditions: the sliding walls' points that follow
        // another wall's projection below are marked from the first step
        // on, and a restart's first step must see what any other sees)
        footOnSurface[i] = bc.projectedByCondition(wallPoints_[i]);
        footSlide[i] = bc.slides()[wallPoints_[i]];
    }
    mapPtr_->distribute(rotation_);
    mapPtr_->distribute(footDisplacement_);
    mapPtr_->distribute(footFixed);
    mapPtr_->distribute(footOnSurface);
    mapPtr_->distribute(footSlide);

    // The outermost points: fixed at their foot's rigid motion, or sliding
    // as their foot does (at their distance from a sliding wall). A foot
    // that its condition projects onto a curved surface slides on its
    // tangent plane in the first fit only: its outermost points slide there
    // too, then follow it (followSurfaces())
    DynamicList<label> surfaceShell;
    for (const label i : shell_)
    {
        const label pointi = zonePoints_[i];
        const label j = zoneFoot_[i];
        if (footFixed[j])
        {
            bc.fix(pointi, zoneRigid(i, &footFixed) - (shift ? (*shift)[pointi] : Zero));
        }
        else if (footSlide[j].first() > 0)
        {
            bc.slide(pointi, footSlide[j]);
            if (footOnSurface[j])
            {
                bc.followSurface(pointi);
                surfaceShell.append(i);
            }
        }
    }
    surfaceShell_.transfer(surfaceShell);
    const List<pointConstraint>& slides = bc.slides();
    // The points of a sliding listed wall within innerDistance of another
    // listed wall (where two walls meet in a corner) keep to the other
    // wall's layers within their own plane: fixed at its foot's rigid
    // motion where that is prescribed, else sliding as that foot too (and
    // following it where it is projected onto a surface), so that the
    // layers of both walls move together
    DynamicList<label> pairSurface;
    DynamicList<pointConstraint> pairSurfaceSlide;
    for (const label i : pairSliding)
    {
        const label p = zonePair_[i];
        const label pointi = zonePoints_[i];
        const label j = pairFoot_[p];
        if (footFixed[j])
        {
            const vector r = rigidMotion(j, pairArm_[p]) - (shift ? (*shift)[pointi] : Zero);
            bc.fix(pointi, slides[pointi].constrainDisplacement(r));
        }
        else if (footSlide[j].first() > 0)
        {
            pointConstraint pc(slides[pointi]);
            pc.combine(footSlide[j]);
            if (footOnSurface[j])
            {
                bc.followSurface(pointi);
                pairSurface.append(i);
                pairSurfaceSlide.append(slides[pointi]);
            }
            bc.slide(pointi, pc);
        }
    }
    pairSurface_.transfer(pairSurface);
    pairSurfaceSlide_.transfer(pairSurfaceSlide);
    anySurfaceShell_ = returnReduce
    (
        surfaceShell_.size() + pairSurface_.size() > 0,
        orOp<bool>()
    );
    // Those on patches whose conditions slide them (a wedge or symmetry
    // plane through the zone) when their foot is prescribed: fixed at the
    // rigid motion within their own plane. (Those that their conditions fix
    // keep their value; those of sliding feet, and on patches that neither
    // fix nor slide, are no control points.)
    for (const label i : patchShell_)
    {
        const label pointi = zonePoints_[i];
        const label j = zoneFoot_[i];
        if (!fixed[pointi] && slides[pointi].first() > 0 && footFixed[j])
        {
            vector r = zoneRigid(i, &footFixed) - (shift ? (*shift)[pointi] : Zero);
            r = slides[pointi].constrainDisplacement(r);
            bc.fix(pointi, r);
        }
    }
    bc.collectControls();
}


void Foam::rigidLayers::followSurfaces
(
    const pointField& points0,
    const solutionFrame& frame,
    vectorField& displacement,
    const vectorField* shift
)
{
    if (!anySurfaceShell_)
    {
        return;
    }
    if (shift)
    {
        fitMovedWalls(points0, displacement + *shift);
    }
    else
    {
        fitMovedWalls(points0, displacement);
    }
    for (const label i : surfaceShell_)
    {
        const label pointi = zonePoints_[i];
        const vector rigid = frame.inFrame(pointi, zoneRigid(i));
        displacement[pointi] = shift ? rigid - (*shift)[pointi] : rigid;
    }
    forAll(pairSurface_, k)
    {
        const label i = pairSurface_[k];
        const label pointi = zonePoints_[i];
        const label p = zonePair_[i];
        vector rigid = rigidMotion(pairFoot_[p], pairArm_[p]);
        rigid = shift ? rigid - (*shift)[pointi] : rigid;
        displacement[pointi] =
            frame.inFrame(pointi, pairSurfaceSlide_[k].constrainDisplacement(rigid));
    }
}


void Foam::rigidLayers::apply
(
    const pointField& points0,
    const boolList& fixed,
    const solutionFrame& frame,
    vectorField& displacement,
    pointField& newPoints,
    const vectorField* shift
)
{
    if (!planned_)
    {
        FatalErrorInFunction
            << "rigidLayers::apply() before addControls(), which plans the"
            << " zone" << exit(FatalError);
    }
    // (the displacement from points0: a rebased morph's is from its base)
    const tmp<vectorField> tfrom0
    (
        shift ? tmp<vectorField>(displacement + *shift) : tmp<vectorField>(displacement)
    );
    const vectorField& from0 = tfrom0();
    if (!transformsFinal_)
    {
        fitMovedWalls(points0, from0);
    }
    if (fixedInZoneToWarn_)
    {
        warnFixedInZone(from0, frame);
    }

    forAll(zonePoints_, i)
    {
        const label pointi = zonePoints_[i];
        if (fixed[pointi])
        {
            continue;
        }
        const scalar w = zoneWeight_[i];
        const vector& d = from0[pointi];
        vector rigid = zoneRigid(i);
        if (w < 1)
        {
            // (rebased: the base's blend carried on, w of the rigid motion
            // and 1 - w of the morph since the base, so that where nothing
            // moved the base is kept)
            rigid =
                shift
              ? (*shift)[pointi] + w*(rigid - baseRigid_[i])
              + (1 - w)*(d - (*shift)[pointi])
              : d + w*(rigid - d);
        }
        rigid = frame.inFrame(pointi, rigid);
        newPoints[pointi] = points0[pointi] + rigid;
        displacement[pointi] = shift ? rigid - (*shift)[pointi] : rigid;
    }
}


void Foam::rigidLayers::markRigid(bitSet& rigid) const
{
    forAll(zonePoints_, i)
    {
        if (zoneWeight_[i] == 1)
        {
            rigid.set(zonePoints_[i]);
        }
    }
}


Foam::labelPair Foam::rigidLayers::nCellsInBlendAndPairs(const labelList& cells) const
{
    // (paired: where the two walls' rigid motions differ there by more
    // than round-off of the point's distances from them; the patches of
    // one body that moves as a whole do not move against each other)
    bitSet blend(mesh_.nPoints()), paired(mesh_.nPoints());
    forAll(zonePoints_, i)
    {
        blend.set(zonePoints_[i], zoneWeight_[i] < 1);
        const label p = zonePair_.size() ? zonePair_[i] : -1;
        if (p >= 0)
        {
            const vector apart =
                rigidMotion(pairFoot_[p], pairArm_[p])
              - rigidMotion(zoneFoot_[i], zoneArm_[i]);
            paired.set
            (
                zonePoints_[i],
                mag(apart) > 1e-9*(mag(zoneArm_[i]) + mag(pairArm_[p]) + outerDistance_)
            );
        }
    }
    labelPair n(0, 0);
    for (const label celli : cells)
    {
        const labelList cellPoints = mesh_.cells()[celli].labels(mesh_.faces());
        const auto any = [&](const bitSet& set)
        {
            return std::any_of
            (
                cellPoints.begin(), cellPoints.end(),
                [&](const label pointi) { return set.test(pointi); }
            );
        };
        n.first() += any(blend);
        n.second() += any(paired);
    }
    reduce(n.first(), sumOp<label>());
    reduce(n.second(), sumOp<label>());
    return n;
}


// ************************************************************************* //
