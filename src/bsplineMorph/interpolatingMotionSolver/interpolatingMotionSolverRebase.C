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
    rebase on: the morph starts from the last step's mesh instead of points0
    once a cell's volume has halved or doubled since the mesh it starts from,
    or where it would invert cells. A smooth field that closes a gap strains
    its middle more than its ends (the walls hold it flat there); morphed in
    stages from the last mesh, each stage's strain acts on the cells as the
    last one left them, so that the squeezed cells are squeezed in proportion
    (their lengths multiply) instead of by the same amount (which takes the
    most squeezed to zero first). The base is a point field, written at the
    write times as <time>/morphBase (binary) and read back on a restart, so
    that decomposePar and reconstructPar carry it as they carry the other
    point fields.

\*---------------------------------------------------------------------------*/

#include "interpolatingMotionSolver.H"
#include "calculatedPointPatchFields.H"

#include <algorithm>

// * * * * * * * * * * * * * * * Local Constants * * * * * * * * * * * * * * //

namespace Foam
{
namespace
{
    //- A cell's volume over its volume in the base (or the inverse) below
    //  which the morph is rebased
    constexpr scalar rebaseVolumeRatio = 0.5;

    const word morphBaseName("morphBase");

    //- The base as written: binary whatever the case's writeFormat, so that
    //  a restart morphs from the same bits
    class morphBase
    :
        public pointVectorField
    {
    public:

        using pointVectorField::pointVectorField;

        virtual bool writeObject
        (
            IOstream::streamFormat,
            IOstream::versionNumber ver,
            IOstream::compressionType,
            const bool valid
        ) const
        {
            return pointVectorField::writeObject
            (
                IOstream::BINARY, ver, IOstream::UNCOMPRESSED, valid
            );
        }
    };
}
}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::interpolatingMotionSolver::readBase(const word& type)
{
    const Time& runTime = mesh().time();
    IOobject io
    (
        morphBaseName,
        runTime.timeName(),
        mesh(),
        IOobject::MUST_READ,
        IOobject::AUTO_WRITE
    );
    const bool found = io.typeHeaderOk<pointVectorField>(true);
    if (!rebase_)
    {
        if (returnReduce(found, orOp<bool>()))
        {
            Info<< type << ": rebase off: " << morphBaseName << " in "
                << runTime.timeName() << " is not read; morphing from the"
                << " initial mesh" << endl;
        }
        return;
    }
    if (!returnReduce(found, orOp<bool>()))
    {
        // (a run that rebased writes its base at every later write time: on
        // a mesh that has moved since the initial one, say what is morphed)
        if (!atPoints(points0()))
        {
            Info<< type << ": rebase on, no " << morphBaseName << " in "
                << runTime.timeName() << ": morphing from the initial mesh"
                << " (as a run that has not rebased before "
                << runTime.timeName() << " does)" << endl;
        }
        return;
    }
    // (the file the handler reads, processorsN/<time>/morphBase collated;
    // where there is none, the one this rank would read)
    const fileName readFrom =
        found ? io.localFilePath(pointVectorField::typeName, false) : io.objectPath();
    if (!returnReduce(found, andOp<bool>()))
    {
        FatalErrorInFunction
            << "rebase on: the morph's base " << morphBaseName << " is in "
            << runTime.timeName() << " of some ranks' directories only ("
            << (found ? "found" : "not found") << " in "
            << runTime.relativePath(readFrom).c_str() << "): decompose"
            << " the case's time " << runTime.timeName() << " again, or remove"
            << " " << morphBaseName << " from every rank's " << runTime.timeName()
            << " to morph from the initial mesh" << exit(FatalError);
    }
    basePtr_.reset(new morphBase(io, pointMesh::New(mesh())));
    shift_ = base() - points0();
    // A base other than the initial mesh comes from a run that moved the
    // mesh and wrote its points at every write time: points read from an
    // earlier time (decomposePar -time '0,T' decomposes the initial mesh
    // with T's fields) would have the run go on from the wrong mesh
    const fileName& pointsFrom = mesh().pointsInstance();
    if
    (
        returnReduce(pointsFrom != runTime.timeName(), orOp<bool>())
     && !returnReduce(base() == points0(), andOp<bool>())
    )
    {
        FatalErrorInFunction
            << "rebase on: " << runTime.relativePath(readFrom).c_str()
            << " is the base of a morph that moved the mesh, but the mesh read"
            << " at time " << runTime.timeName() << " is that of "
            << pointsFrom.c_str() << " (no polyMesh/points in " << runTime.timeName()
            << "): the run would go on from the wrong mesh. Give "
            << runTime.timeName() << " its moved points (decomposePar"
            << " -latestTime, or -time " << runTime.timeName() << " alone,"
            << " decomposes that time's mesh), or remove " << morphBaseName
            << " from " << runTime.timeName() << " to morph from the initial"
            << " mesh" << exit(FatalError);
    }
    // The base is a mesh the run morphed from: none of its cells inverted
    // (a base of other points, or of these in another order, inverts them;
    // with invertedCells warn a run may have gone on with some)
    baseVolumes_ = cellVolumesOf(base());
    const label nInverted = returnReduce
    (
        label(std::count_if
        (
            baseVolumes_.cbegin(), baseVolumes_.cend(),
            [](const scalar v) { return !(v > 0); }
        )),
        sumOp<label>()
    );
    if (nInverted && invertedCellsFatal_)
    {
        FatalErrorInFunction
            << "rebase on: " << runTime.relativePath(readFrom).c_str()
            << " inverts " << nInverted << " cells of this mesh: it is not the"
            << " base of a morph of this mesh (its points were renumbered, or"
            << " it comes from another mesh). Remove " << morphBaseName
            << " from " << runTime.timeName() << " to morph from the initial"
            << " mesh" << exit(FatalError);
    }
    Info<< type << ": rebased, morphing from the mesh in "
        << runTime.relativePath(readFrom).c_str() << endl;
}


Foam::tmp<Foam::scalarField> Foam::interpolatingMotionSolver::cellVolumesOf
(
    const pointField& points
) const
{
    tmp<scalarField> tV(new scalarField(mesh().nCells()));
    scalarField& V = tV.ref();
    point centre;
    forAll(V, celli)
    {
        V[celli] = invertedCellCheck::checkMeshVolume(mesh(), points, celli, centre);
    }
    return tV;
}


bool Foam::interpolatingMotionSolver::atPoints(const pointField& b) const
{
    const pointField& p = mesh().points();
    bool same = true;
    forAll(p, pointi)
    {
        if (p[pointi] != b[pointi])
        {
            same = false;
            break;
        }
    }
    return returnReduce(same, andOp<bool>());
}


Foam::string Foam::interpolatingMotionSolver::baseName() const
{
    return basePtr_.valid() ? "the mesh the morph was rebased on" : "the initial mesh";
}


void Foam::interpolatingMotionSolver::rebaseIfStrained()
{
    // The mesh's volumes (OpenFOAM's: the flow solver has them), against
    // the base's: those of the mesh when it was taken, else (the first
    // step) formed from the base's points as OpenFOAM forms them
    const scalarField& V = mesh().cellVolumes();
    if (baseVolumes_.size() != V.size())
    {
        baseVolumes_ = cellVolumesOf(base());
    }
    scalar least = 1;
    forAll(V, celli)
    {
        const scalar r = V[celli]/baseVolumes_[celli];
        least = min(least, r > 0 ? min(r, 1/r) : 0);
    }
    reduce(least, minOp<scalar>());
    if (least < rebaseVolumeRatio)
    {
        // (a volume of the other sign or none: an inverted cell, now or in
        // the base, which invertedCells warn let through)
        rebase
        (
            least > 0
          ? "a cell's volume changed by a factor " + Foam::name(1/max(least, VSMALL))
          + " since " + baseName()
          : "a cell's volume changed sign since " + baseName()
          + " (invertedCells warn lets inverted cells through)"
        );
    }
}


bool Foam::interpolatingMotionSolver::rebase(const string& why)
{
    // (nothing to gain where the mesh is the base already: the first step,
    // or a step morphed again)
    if (atPoints(base()))
    {
        return false;
    }
    const pointField& p = mesh().points();
    const Time& runTime = mesh().time();
    Info<< type() << ": " << why.c_str() << " (rebase on), at time "
        << runTime.timeName()
        << ": rebased on the last step's mesh (planned again)" << endl;
    if (rigidLayersPtr_)
    {
        rigidLayersPtr_->rebased();
    }
    if (!basePtr_.valid())
    {
        basePtr_.reset
        (
            new morphBase
            (
                IOobject
                (
                    morphBaseName,
                    runTime.timeName(),
                    mesh(),
                    IOobject::NO_READ,
                    IOobject::AUTO_WRITE
                ),
                pointMesh::New(mesh()),
                dimensionedVector(dimLength, Zero),
                calculatedPointPatchVectorField::typeName
            )
        );
    }
    basePtr_().primitiveFieldRef() = p;
    shift_ = base() - points0();
    baseVolumes_ = mesh().cellVolumes();
    // The plans are made again from the new base (the rigid layers' stays:
    // its zone, feet and weights are those of points0)
    constraintsPtr_.reset();
    refitPtr_.reset();
    evalPoints_.clear();
    evalXyz_.clear();
    clearPlan();
    return true;
}


// ************************************************************************* //
