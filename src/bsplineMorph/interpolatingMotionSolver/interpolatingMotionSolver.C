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

#include "interpolatingMotionSolver.H"
#include "clockTime.H"
#include "Enum.H"
#include "mapPolyMesh.H"
#include "hugePages.hpp"

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

namespace Foam
{
    defineTypeNameAndDebug(interpolatingMotionSolver, 0);

    namespace
    {
        enum class onInverted { fatal, warn };
        const Enum<onInverted> onInvertedNames
        ({
            { onInverted::fatal, "fatal" },
            { onInverted::warn, "warn" },
        });

        bool readInvertedCellsFatal(const dictionary& dict)
        {
            return onInvertedNames.lookupOrDefault
            (
                "invertedCells", dict, onInverted::fatal
            ) == onInverted::fatal;
        }

        //- Size a mesh-sized work array swept every step; when it is
        //  allocated, ask for huge pages before it is first written (as the
        //  core's arrays; best effort: malloc may hand out memory written
        //  before, which keeps its pages)
        template<class T>
        void setSizeOnHugePages(List<T>& list, const label n)
        {
            if (list.size() != n)
            {
                list.setSize(n);
                mba::adviseHugePages(list.data(), n*sizeof(T));
            }
        }
    }
}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

Foam::label Foam::interpolatingMotionSolver::nInvertedCells
(
    const pointField& points
) const
{
    signedCellVolumes(mesh(), points, cellVol_);
    label n = 0;
    for (const scalar v : cellVol_)
    {
        if (!(v > 0))
        {
            ++n;
        }
    }
    return returnReduce(n, sumOp<label>());
}


void Foam::interpolatingMotionSolver::setEvalPoints()
{
    const boolList& fixed = constraintsPtr_->fixed();
    DynamicList<label> points(fixed.size());
    forAll(fixed, pointi)
    {
        if (!fixed[pointi]) points.append(pointi);
    }
    if (points == evalPoints_ && !evalXyz_.empty())
    {
        return;
    }
    evalPoints_.transfer(points);
    const labelList& dirs = constraintsPtr_->directions();
    const pointField& p0 = points0();
    evalXyz_.clear();
    evalXyz_.reserve(dirs.size()*evalPoints_.size());
    for (const label pointi : evalPoints_)
    {
        for (const label d : dirs) evalXyz_.push_back(p0[pointi][d]);
    }
    // The re-fit plan evaluates these points too
    planned_[1] = false;
}


std::string Foam::interpolatingMotionSolver::interpolateInto
(
    vectorField& displacement
)
{
    const std::string summary = interpolate(values_);
    // The interpolated points' displacement (zero outside the solution
    // directions) and their moved points, in one pass
    // (each component read from its packed value or zero, into registers:
    // a vector filled through d[dirs[k]] stalls every point on its stores)
    const labelList& dirs = constraintsPtr_->directions();
    const label nd = dirs.size();
    label at[3] = {-1, -1, -1};         // packed position of each direction
    forAll(dirs, k)
    {
        at[dirs[k]] = k;
    }
    const pointField& p0 = points0();
    const double* v = values_.data();
    forAll(evalPoints_, i)
    {
        const label pointi = evalPoints_[i];
        const vector d
        (
            at[0] < 0 ? 0 : v[at[0]],
            at[1] < 0 ? 0 : v[at[1]],
            at[2] < 0 ? 0 : v[at[2]]
        );
        v += nd;
        displacement[pointi] = d;
        newPoints_[pointi] = p0[pointi] + d;
    }
    return summary;
}


void Foam::interpolatingMotionSolver::use(const label slot, const bool changed)
{
    slot_ = slot;
    if (returnReduce(changed, orOp<bool>()) || !planned_[slot])
    {
        if (slot == 0)
        {
            setEvalPoints();
        }
        buildPlan();
        planned_[slot] = true;
    }
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::interpolatingMotionSolver::interpolatingMotionSolver
(
    const polyMesh& mesh,
    const IOdictionary& dict,
    const word& type
)
:
    displacementMotionSolver(mesh, dict, type),
    invertedCellsFatal_(readInvertedCellsFatal(coeffDict())),
    rigidLayersPtr_(rigidLayers::New(mesh, coeffDict())),
    planned_{false, false},
    slot_(0)
{}


Foam::interpolatingMotionSolver::interpolatingMotionSolver
(
    const polyMesh& mesh,
    const IOdictionary& dict,
    const pointVectorField& pointDisplacement,
    const pointIOField& points0,
    const word& type
)
:
    displacementMotionSolver(mesh, dict, pointDisplacement, points0, type),
    invertedCellsFatal_(readInvertedCellsFatal(coeffDict())),
    rigidLayersPtr_(rigidLayers::New(mesh, coeffDict())),
    planned_{false, false},
    slot_(0)
{}


// * * * * * * * * * * * * * * * * Destructor  * * * * * * * * * * * * * * * //

Foam::interpolatingMotionSolver::~interpolatingMotionSolver()
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::tmp<Foam::pointField>
Foam::interpolatingMotionSolver::curPoints() const
{
    if (newPoints_.size() == points0().size())
    {
        return tmp<pointField>(newPoints_);
    }
    tmp<pointField> tcurPoints(points0() + pointDisplacement_.primitiveField());
    twoDCorrectPoints(tcurPoints.ref());
    return tcurPoints;
}


void Foam::interpolatingMotionSolver::solve()
{
    const clockTime timer;
    std::string summary;

    // The boundary conditions give the prescribed displacements
    pointDisplacement_.boundaryFieldRef().updateCoeffs();
    pointDisplacement_.correctBoundaryConditions();

    // The control set, updated in place after the first step (its
    // mesh-sized arrays kept); whether its points or masks changed
    const bool first = !constraintsPtr_;
    labelList points;
    std::vector<std::uint8_t> mask;
    if (first)
    {
        constraintsPtr_.reset(new boundaryConstraints(pointDisplacement_));
    }
    else
    {
        points = constraintsPtr_->controlPoints();
        mask = constraintsPtr_->mask();
        constraintsPtr_->update(pointDisplacement_);
    }
    // The rigid layers' outermost points are control points too
    if (rigidLayersPtr_)
    {
        if (first)
        {
            rigidLayersPtr_->checkConstrained(*constraintsPtr_);
        }
        rigidLayersPtr_->addControls(*constraintsPtr_, points0());
    }
    const bool changed = first || !constraintsPtr_->sameControls(points, mask);

    // The displacement is worked out in pointDisplacement's own values (the
    // conditions have been read), and the moved points beside it: every point
    // is set below, the interpolated ones by interpolateInto (zero outside the
    // solution directions), the fixed ones by constrain, which also zeroes the
    // directions a 2D mesh does not solve for
    vectorField& displacement = pointDisplacement_.primitiveFieldRef();
    const pointField& p0 = points0();
    setSizeOnHugePages(newPoints_, p0.size());
    slot_ = 0;
    if (constraintsPtr_->nControlGlobal() == 0)
    {
        WarningInFunction
            << "No control points: no patch of pointDisplacement fixes a value"
            << " or slides; the mesh keeps its initial points" << endl;
        displacement = Zero;
        newPoints_ = p0;
        clearPlan();
    }
    else
    {
        use(0, changed);
        summary = interpolateInto(displacement);

        // Sliding planes not along the axes: project, then fit again with
        // the projected points as control points, so that the interpolant
        // (not only those points) follows the planes
        if (constraintsPtr_->nProjectedGlobal() > 0)
        {
            constraintsPtr_->constrain(displacement);
            std::unique_ptr<boundaryConstraints> refit
            (
                new boundaryConstraints(*constraintsPtr_, displacement)
            );
            const bool refitChanged = !refitPtr_
             || !refit->sameControls(refitPtr_->controlPoints(), refitPtr_->mask());
            refitPtr_ = std::move(refit);
            use(1, refitChanged);
            summary += "; re-fit with the projected sliding points: " + interpolateInto(displacement);
            slot_ = 0;
        }

        // The layers near the listed walls move with them (from the walls'
        // final displacement: the boundary points constrained first)
        if (rigidLayersPtr_)
        {
            constraintsPtr_->constrain(displacement);
            rigidLayersPtr_->apply
            (
                p0,
                constraintsPtr_->fixed(),
                constraintsPtr_->directions(),
                displacement,
                newPoints_
            );
        }
    }
    // The points the conditions fix or constrain (the interpolated ones
    // moved already)
    constraintsPtr_->constrain(displacement);
    for (const label pointi : constraintsPtr_->boundaryPoints())
    {
        newPoints_[pointi] = p0[pointi] + displacement[pointi];
    }
    twoDCorrectPoints(newPoints_);
    const clockTime checkTimer;
    const label nInverted = nInvertedCells(newPoints_);
    const scalar checkSeconds = checkTimer.elapsedTime();
    if (nInverted > 0)
    {
        if (invertedCellsFatal_)
        {
            FatalErrorInFunction
                << "The prescribed motion inverts " << nInverted
                << " cells at time " << mesh().time().timeName()
                << " (non-positive volume); the mesh is not moved."
                << " Smaller motion steps, other " << type() << "Coeffs"
                << " settings, or invertedCells warn (to continue anyway) are"
                << " the options" << exit(FatalError);
        }
        WarningInFunction
            << "The morphed mesh has " << nInverted << " inverted cells at time "
            << mesh().time().timeName() << endl;
    }

    // Evaluate the conditions (fixed values, processor patches), then keep
    // the constrained interpolant: slip conditions would re-project their
    // points with their own point normals, which on a rank hold only that
    // rank's faces and so differ between decompositions (the conditions
    // write at their patches' points only: those are restored)
    const labelList& bp = constraintsPtr_->boundaryPoints();
    boundaryValues_.setSize(bp.size());
    forAll(bp, i)
    {
        boundaryValues_[i] = displacement[bp[i]];
    }
    pointDisplacement_.correctBoundaryConditions();
    forAll(bp, i)
    {
        displacement[bp[i]] = boundaryValues_[i];
    }

    if (!summary.empty())
    {
        Info<< type() << ": " << summary.c_str() << ", inverted-cell check "
            << checkSeconds << " s, " << timer.elapsedTime() << " s" << endl;
    }
}


void Foam::interpolatingMotionSolver::signedCellVolumes
(
    const polyMesh& mesh,
    const pointField& points,
    scalarField& vol
)
{
    // Signed cell volumes (cell::mag sums absolute pyramid volumes, so it
    // never sees an inverted cell): the divergence theorem over the faces,
    // V = sum over a cell's faces of area vector . (face point - x0)/3 for
    // any x0 (a closed cell's area vectors add up to 0), each face as its
    // area vector (twice it: for a quad the cross product of its diagonals,
    // else the triangles about its first vertex) and its vertex mean, x0 the
    // centre of the mesh's bounds (for every cell: one term per face, added
    // to its owner and taken from its neighbour). Exact for planar faces;
    // one pass over the faces, no square roots, no face arrays.
    const faceList& faces = mesh.faces();
    const labelList& own = mesh.faceOwner();
    const labelList& nei = mesh.faceNeighbour();
    const point x0 = mesh.bounds().centre();
    const scalar sixth = 1.0/6;   // (a third, of twice the area)
    setSizeOnHugePages(vol, mesh.nCells());
    vol = 0;
    // (faces come in owner order: a face's term goes to its owner through a
    // register while the owner stays the same; added to memory face after
    // face, each would wait for the previous one's store)
    label owner = own.empty() ? -1 : own[0];
    scalar ownerSum = 0;
    forAll(faces, facei)
    {
        // (a face's labels lie elsewhere: asked for some faces ahead)
        if (facei + 32 < faces.size()) __builtin_prefetch(faces[facei + 32].cdata());
        const face& f = faces[facei];
        const point& p0 = points[f[0]];
        vector mean, area;
        if (f.size() == 4)
        {
            const point& p1 = points[f[1]];
            const point& p2 = points[f[2]];
            const point& p3 = points[f[3]];
            mean = 0.25*(p0 + p1 + p2 + p3);
            area = (p2 - p0) ^ (p3 - p1);
        }
        else
        {
            vector sum = p0;
            area = Zero;
            for (label i = 1; i < f.size(); ++i)
            {
                const point& p = points[f[i]];
                sum += p;
                if (i + 1 < f.size())
                {
                    area += (p - p0) ^ (points[f[i + 1]] - p0);
                }
            }
            mean = sum/f.size();
        }
        const scalar v = (area & (mean - x0))*sixth;
        if (own[facei] != owner)
        {
            vol[owner] += ownerSum;
            owner = own[facei];
            ownerSum = 0;
        }
        ownerSum += v;
        if (facei < nei.size())
        {
            vol[nei[facei]] -= v;
        }
    }
    if (owner >= 0)
    {
        vol[owner] += ownerSum;
    }
}


void Foam::interpolatingMotionSolver::movePoints(const pointField& p)
{
    displacementMotionSolver::movePoints(p);
    newPoints_.clear();
    clearPlan();
}


void Foam::interpolatingMotionSolver::updateMesh(const mapPolyMesh& mpm)
{
    displacementMotionSolver::updateMesh(mpm);
    // points0 changed: the plans are rebuilt at the next solve
    if (rigidLayersPtr_)
    {
        rigidLayersPtr_->clearPlan();
    }
    constraintsPtr_.reset();
    refitPtr_.reset();
    evalPoints_.clear();
    evalXyz_.clear();
    newPoints_.clear();
    clearPlan();
}


// ************************************************************************* //
