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
#include "OStringStream.H"
#include "OFstream.H"
#include "OSspecific.H"
#include "coeffsInput.H"
#include "logPrecision.H"
#include "hugePageLists.H"
#include <cmath>

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
            return coeffsInput::getEnum
            (
                dict, "invertedCells", onInvertedNames, onInverted::fatal
            ) == onInverted::fatal;
        }

        // (below 90 deg: faces at a point that turn back on each other, whose
        // normals cancel, keep a mean normal well above round-off)
        scalar readCurvedSlipAngle(const dictionary& dict)
        {
            return coeffsInput::getInRange<scalar>
            (
                dict, "curvedSlipAngle", 30, 0, 89
            );
        }
    }
}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

Foam::scalar Foam::interpolatingMotionSolver::checkCells
(
    const pointField& points,
    invertedCellCheck::result& r
)
{
    const clockTime timer;
    if (!checkPtr_)
    {
        checkPtr_.reset(new invertedCellCheck(mesh()));
    }
    r = checkPtr_->check(points);
    return timer.elapsedTime();
}


void Foam::interpolatingMotionSolver::refuseInverted
(
    const invertedCellCheck::result& r
) const
{
    OStringStream what;
    // (the box's corners in enough digits to tell them apart where the
    // mesh lies far from the origin)
    const scalar far = max(mag(r.where.min()), mag(r.where.max()));
    const scalar span = r.where.mag() > 0 ? r.where.mag() : 1e-3*mesh().bounds().mag();
    const int digits = 3 + std::ceil(std::log10(max(far, span)/span));
    what.precision(min(max(digits, int(what.precision())), 17));
    what<< r.nInvalid << " cells at time " << mesh().time().timeName()
        << " (" << r.nNonPositive << " of non-positive volume, "
        << r.nFolded << " folded: positive volume but a face pyramid"
        << " wrongly oriented against the cell centre, as checkMesh counts"
        << " them; cells (their points' means) within " << r.where << ")";
    const labelPair nLayers =
        rigidLayersPtr_ ? rigidLayersPtr_->nCellsInBlendAndPairs(r.cells) : labelPair(0, 0);
    if (nLayers.first())
    {
        what<< "; " << nLayers.first() << " of them have a point in the"
            << " rigidLayers blend (between innerDistance and outerDistance),"
            << " which takes up the difference between the layers' rigid"
            << " motion and the interpolated field: another outerDistance"
            << " spreads it otherwise (under a crease of a deforming wall a"
            << " narrower blend (outerDistance nearer innerDistance) strains"
            << " it less)";
    }
    if (nLayers.second())
    {
        what<< "; " << nLayers.second() << " of them have a point near two"
            << " listed walls, where the walls' rigid motions blend: walls"
            << " that move against each other need room between their rigid"
            << " layers (a smaller innerDistance)";
    }
    if (rigidLayersPtr_ && rigidLayersPtr_->facingGapsWarned())
    {
        what<< "; listed walls face each other across gaps narrower than"
            << " twice outerDistance (the warning at the plan): an"
            << " outerDistance of half the narrowest gap gives the cells"
            << " between them the most room";
    }
    if (invertedCellsFatal_)
    {
        // (without rebase the morph is from the initial mesh whatever the
        // steps: smaller ones change nothing)
        FatalErrorInFunction
            << "The prescribed motion"
            << (rebase_ ? ", morphed from the last step's mesh (rebase on)," : "")
            << " inverts " << what.str().c_str()
            << "; the mesh is not moved. "
            << (rebase_ ? "Smaller motion steps, other " : "Other ")
            << type() << "Coeffs settings, "
            << (rebase_ ? "" : "rebase on (to morph from the last step's mesh), ")
            << "or invertedCells warn (to continue anyway) are"
            << " the options" << exit(FatalError);
    }
    WarningInFunction
        << "The morphed mesh has " << r.nInvalid << " inverted cells: "
        << what.str().c_str() << endl;
}


void Foam::interpolatingMotionSolver::setEvalPoints()
{
    // The points the conditions do not fix, less the rigid layers' points
    // within innerDistance that no condition constrains: those move with
    // their wall whatever the interpolant gives them (the sliding ones are
    // interpolated: they are projected, and may be feet or re-fit points)
    const boundaryConstraints& bc = *constraintsPtr_;
    const boolList& fixed = bc.fixed();
    bitSet rigid(fixed.size());
    if (rigidLayersPtr_)
    {
        rigidLayersPtr_->markRigid(rigid);
    }
    DynamicList<label> points(fixed.size());
    forAll(fixed, pointi)
    {
        if (!fixed[pointi] && !(rigid.test(pointi) && !bc.constrains(pointi)))
        {
            points.append(pointi);
        }
    }
    if (points == evalPoints_ && !evalXyz_.empty())
    {
        return;
    }
    evalPoints_.transfer(points);
    const solutionFrame& frame = constraintsPtr_->frame();
    const pointField& p0 = base();
    reserveOnHugePages(evalXyz_, frame.size()*evalPoints_.size());
    for (const label pointi : evalPoints_)
    {
        frame.appendCoordinates(p0[pointi], evalXyz_);
    }
    // The mesh-sized lists that every step sweeps, on huge pages (values_
    // keeps its storage while its size does; newPoints_ was advised when it
    // was sized)
    reserveOnHugePages(values_, evalXyz_.size());
    values_.assign(evalXyz_.size(), 0);
    onHugePages(evalXyz_);
    onHugePages(values_);
    onHugePages(evalPoints_);
    onHugePages(p0);
    onHugePages(pointDisplacement_.primitiveField());
    onHugePages(newPoints_);
    // The re-fit interpolator evaluates these points too
    refitInterpolatorPtr_.reset();
}


Foam::interpolationReport Foam::interpolatingMotionSolver::interpolateInto
(
    boundaryInterpolator& interpolator,
    const boundaryConstraints& bc,
    vectorField& displacement
)
{
    const interpolationReport report = interpolator.interpolate(bc, values_);
    // The interpolated points' displacement (zero outside the solution
    // directions) and their moved points, in one pass
    const solutionFrame& frame = constraintsPtr_->frame();
    const pointField& p0 = base();
    const double* v = values_.data();
    if (frame.axisymmetric())
    {
        forAll(evalPoints_, i)
        {
            const label pointi = evalPoints_[i];
            vector b[3];
            frame.basis(pointi, b);
            const vector d(v[0]*b[0] + v[1]*b[1]);
            v += 2;
            displacement[pointi] = d;
            newPoints_[pointi] = p0[pointi] + d;
        }
        return report;
    }
    // (each component read from its packed value or zero, into registers:
    // a vector filled through d[dirs[k]] stalls every point on its stores)
    const labelList& dirs = frame.directions();
    const label nd = dirs.size();
    label at[3] = {-1, -1, -1};         // packed position of each direction
    forAll(dirs, k)
    {
        at[dirs[k]] = k;
    }
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
    return report;
}


void Foam::interpolatingMotionSolver::plan
(
    std::unique_ptr<boundaryInterpolator>& interpolator,
    const boundaryConstraints& bc,
    const bool refit,
    const bool changed
)
{
    // (the communicator's all-gather: ceil(log2 N) latencies, a tree's 2 log2 N)
    if (comm_.max(changed ? 1 : 0) > 0 || !interpolator)
    {
        if (!refit)
        {
            setEvalPoints();
        }
        interpolator.reset();
        interpolator = newInterpolator(bc, refit);
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
    rebase_(coeffDict().lookupOrDefault<bool>("rebase", false)),
    curvedSlipAngle_(readCurvedSlipAngle(coeffDict())),
    rigidLayersPtr_(rigidLayers::New(mesh, coeffDict())),
    checkZoneBorder_(false)
{
    boundaryConstraints::checkCouplings(this->pointDisplacement(), this->points0(), type);
    readBase(type);
    findZoneBorder();
}


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
    rebase_(coeffDict().lookupOrDefault<bool>("rebase", false)),
    curvedSlipAngle_(readCurvedSlipAngle(coeffDict())),
    rigidLayersPtr_(rigidLayers::New(mesh, coeffDict())),
    checkZoneBorder_(false)
{
    boundaryConstraints::checkCouplings(this->pointDisplacement(), this->points0(), type);
    readBase(type);
    findZoneBorder();
}


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


bool Foam::interpolatingMotionSolver::updateControls()
{
    // The control set, updated in place after the first step (its
    // mesh-sized arrays kept); whether its points or masks changed
    const bool first = !constraintsPtr_;
    labelList points;
    std::vector<std::uint8_t> mask;
    if (first)
    {
        constraintsPtr_.reset
        (
            new boundaryConstraints
            (
                pointDisplacement_, points0(), base(), curvedSlipAngle_, shift()
            )
        );
    }
    else
    {
        points = constraintsPtr_->controlPoints();
        mask = constraintsPtr_->mask();
        constraintsPtr_->update(pointDisplacement_, shift());
    }
    // The rigid layers' outermost points are control points too
    if (rigidLayersPtr_)
    {
        if (first)
        {
            rigidLayersPtr_->checkConstrained(*constraintsPtr_);
        }
        rigidLayersPtr_->addControls(*constraintsPtr_, points0(), shift());
    }
    if (checkZoneBorder_)
    {
        warnZoneBorder();
    }
    return first || !constraintsPtr_->sameControls(points, mask);
}


void Foam::interpolatingMotionSolver::projectOntoSurfaces
(
    vectorField& displacement
)
{
    // (the conditions' own evaluation, from the displacement from points0,
    // written at their points; the displacement is pointDisplacement's)
    // (each patch's projection synced before the next one's, which may
    // project the points they share further: the same chain on every rank)
    constraintsPtr_->slideBeforeProjection(displacement);
    const labelList& patches = constraintsPtr_->projectingPatches();
    forAll(patches, k)
    {
        pointPatchVectorField& pf = pointDisplacement_.boundaryFieldRef()[patches[k]];
        const labelList& meshPoints = pf.patch().meshPoints();
        if (shift())
        {
            for (const label pointi : meshPoints)
            {
                displacement[pointi] += shift_[pointi];
            }
        }
        pf.evaluate();
        if (shift())
        {
            for (const label pointi : meshPoints)
            {
                displacement[pointi] -= shift_[pointi];
            }
        }
        constraintsPtr_->syncProjected(k, displacement);
    }
}


Foam::interpolationReport Foam::interpolatingMotionSolver::interpolateField
(
    vectorField& displacement,
    const bool changed
)
{
    boundaryConstraints& bc = *constraintsPtr_;
    plan(interpolatorPtr_, bc, false, changed);
    interpolationReport report = interpolateInto(*interpolatorPtr_, bc, displacement);

    // Sliding planes not along the axes and surfaces: project; cyclic
    // couplings: the joined points' mean; the rigid layers' outermost points
    // over a projected wall: its rigid motion. Then fit again with those
    // points as control points, so that the interpolant (not only those
    // points) follows the planes and is continuous across the cyclic pairs
    if (bc.nRefitGlobal() > 0)
    {
        projectOntoSurfaces(displacement);
        bc.constrain(displacement);
        bc.matchCyclic(displacement);
        if (rigidLayersPtr_)
        {
            rigidLayersPtr_->followSurfaces(points0(), bc.frame(), displacement, shift());
        }
        std::unique_ptr<boundaryConstraints> refit
        (
            new boundaryConstraints(bc, displacement)
        );
        const bool refitChanged = !refitPtr_
         || !refit->sameControls(refitPtr_->controlPoints(), refitPtr_->mask());
        refitPtr_ = std::move(refit);
        plan(refitInterpolatorPtr_, *refitPtr_, true, refitChanged);
        const interpolationReport refitReport =
            interpolateInto(*refitInterpolatorPtr_, *refitPtr_, displacement);
        // (the re-fit meets its fixed points to its tolerance: those the
        // conditions project onto surfaces are put back onto them)
        projectOntoSurfaces(displacement);
        report.summary +=
            bc.nCyclicGlobal() > 0
          ? "; re-fit with the projected sliding and cyclic points: "
          : "; re-fit with the projected sliding points: ";
        report.summary += refitReport.summary;
        for (const auto& figure : refitReport.figures)
        {
            report.add("refit_" + figure.first, figure.second);
        }
    }

    // The layers near the listed walls move with them (from the walls'
    // final displacement: the boundary points constrained first)
    if (rigidLayersPtr_)
    {
        bc.constrain(displacement);
        rigidLayersPtr_->apply
        (
            points0(),
            bc.fixed(),
            bc.frame(),
            displacement,
            newPoints_,
            shift()
        );
    }
    return report;
}


void Foam::interpolatingMotionSolver::moveBoundaryPoints
(
    vectorField& displacement
)
{
    // The points the conditions fix or constrain (the interpolated ones
    // moved already); the cyclic pairs matched exactly
    const pointField& p0 = base();
    constraintsPtr_->matchCyclic(displacement);
    constraintsPtr_->constrain(displacement);
    for (const label pointi : constraintsPtr_->boundaryPoints())
    {
        newPoints_[pointi] = p0[pointi] + displacement[pointi];
    }
    twoDCorrectPoints(newPoints_);
}


void Foam::interpolatingMotionSolver::correctBoundaryValues
(
    vectorField& displacement
)
{
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
    // (updated at the step's start, in solve(): marked so, the
    // evaluation does not update them again, which would advance a
    // condition with a state, such as sixDoFRigidBodyDisplacement's body, a
    // second time past the values the mesh moved with)
    for (pointPatchVectorField& pf : pointDisplacement_.boundaryFieldRef())
    {
        pf.pointPatchField<vector>::updateCoeffs();
    }
    pointDisplacement_.correctBoundaryConditions();
    forAll(bp, i)
    {
        displacement[bp[i]] = boundaryValues_[i];
    }
}


Foam::interpolationReport Foam::interpolatingMotionSolver::morph
(
    vectorField& displacement,
    const bool changed
)
{
    // The displacement is worked out in pointDisplacement's own values (the
    // conditions have been read), and the moved points beside it: every point
    // is set, the interpolated ones by interpolateField (zero outside the
    // solution directions), the boundary ones by moveBoundaryPoints (after
    // this), which also zeroes the directions a 2D mesh does not solve for
    setSizeOnHugePages(newPoints_, points0().size());
    interpolationReport report;
    if (constraintsPtr_->nControlGlobal() == 0)
    {
        WarningInFunction
            << "No control points: no patch of pointDisplacement fixes a value"
            << " or slides; the mesh keeps its initial points" << endl;
        displacement = Zero;
        newPoints_ = base();
        clearPlan();
    }
    else
    {
        report = interpolateField(displacement, changed);
    }
    return report;
}


void Foam::interpolatingMotionSolver::solve()
{
    const clockTime timer;
    if (rebase_)
    {
        const logPrecision digits;
        rebaseIfStrained();
    }
    vectorField& displacement = pointDisplacement_.primitiveFieldRef();
    interpolationReport report;
    invertedCellCheck::result inverted;
    scalar conditionsSeconds = 0, boundarySeconds = 0, checkSeconds = 0;
    // The boundary conditions give the prescribed displacements (updated
    // once a step: a condition with a state advances it at each update; it
    // logs that at the case's precision, the solver's lines at 6 digits)
    pointDisplacement_.boundaryFieldRef().updateCoeffs();
    pointDisplacement_.correctBoundaryConditions();
    const logPrecision digits;
    scalar before = 0;
    // The morph, and (rebase on) once more from the last step's mesh where
    // it would invert cells
    for (bool retry = rebase_; ; retry = false)
    {
        const bool changed = updateControls();
        conditionsSeconds += timer.elapsedTime() - before;
        report = morph(displacement, changed);
        before = timer.elapsedTime();
        moveBoundaryPoints(displacement);
        boundarySeconds += timer.elapsedTime() - before;
        checkSeconds += checkCells(newPoints_, inverted);
        if
        (
            !retry || inverted.nInvalid == 0
         || !rebase
            (
                "the morph from " + baseName() + " would invert "
              + Foam::name(inverted.nInvalid) + " cells"
            )
        )
        {
            break;
        }
        before = timer.elapsedTime();
    }
    if (inverted.nInvalid > 0)
    {
        refuseInverted(inverted);
    }
    const label nInvalid = inverted.nInvalid;
    before = timer.elapsedTime();
    // (the displacement from points0: pointDisplacement's meaning)
    if (shift())
    {
        displacement += shift_;
    }
    correctBoundaryValues(displacement);
    boundarySeconds += timer.elapsedTime() - before;

    if (!report.summary.empty())
    {
        const scalar seconds = timer.elapsedTime();
        Info<< type() << ": " << report.summary.c_str() << ", inverted-cell check "
            << checkSeconds << " s, " << seconds << " s" << endl;
        report.add("invalidCells", nInvalid);
        report.add("check_s", checkSeconds);
        report.add("conditions_s", conditionsSeconds);
        report.add("boundary_s", boundarySeconds);
        report.add("solve_s", seconds);
        writeTable(report);
    }
}


void Foam::interpolatingMotionSolver::writeTable
(
    const interpolationReport& report
)
{
    if (!Pstream::master())
    {
        return;
    }
    const Time& runTime = mesh().time();
    if (!tablePtr_)
    {
        const fileName dir =
            runTime.globalPath()/"postProcessing"/type()
           /runTime.timeName(runTime.startTime().value());
        mkDir(dir);
        tablePtr_.reset(new OFstream(dir/(type() + ".dat")));
        tablePtr_().precision(10);
        tableColumns_.clear();
    }
    OFstream& os = tablePtr_();
    // (a header whenever the columns change: a re-fit set that appears)
    wordList columns(report.figures.size());
    forAll(columns, i)
    {
        columns[i] = report.figures[i].first;
    }
    if (columns != tableColumns_)
    {
        os  << "# Time";
        for (const word& c : columns) os << tab << c;
        os  << nl;
        tableColumns_ = columns;
    }
    os  << runTime.timeName();
    for (const auto& figure : report.figures) os << tab << figure.second;
    os  << endl;
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
    // points0 changed: the plans are rebuilt at the next solve, from it
    basePtr_.clear();
    shift_.clear();
    baseVolumes_.clear();
    if (rigidLayersPtr_)
    {
        rigidLayersPtr_->clearPlan();
    }
    constraintsPtr_.reset();
    refitPtr_.reset();
    checkPtr_.reset();
    evalPoints_.clear();
    evalXyz_.clear();
    newPoints_.clear();
    clearPlan();
}


// ************************************************************************* //
