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

#include "solutionFrame.H"
#include "wedgePolyPatch.H"
#include "emptyPolyPatch.H"
#include "bitSet.H"
#include "DynamicList.H"
#include "SubField.H"

#include <cmath>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    //- A unit vector whose largest component is positive
    Foam::vector canonical(Foam::vector v)
    {
        using namespace Foam;
        v.normalise();
        direction big = 0;
        for (direction c = 1; c < 3; ++c)
        {
            if (mag(v[c]) > mag(v[big])) big = c;
        }
        return v[big] < 0 ? -v : v;
    }
}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::solutionFrame::checkOneCellThick(const polyMesh& mesh)
{
    // Every point of a 2D mesh lies on its empty patches (one cell between
    // them): otherwise the points between them would be morphed in the plane
    // alone, and OpenFOAM's twoDPointCorrector would move them onto the
    // empty planes
    bitSet onEmpty(mesh.nPoints());
    wordList names;
    for (const polyPatch& pp : mesh.boundaryMesh())
    {
        if (isA<emptyPolyPatch>(pp))
        {
            onEmpty.set(pp.meshPoints());
            names.append(pp.name());
        }
    }
    const label off = returnReduce(mesh.nPoints() - label(onEmpty.count()), sumOp<label>());
    if (off > 0)
    {
        FatalErrorInFunction
            << "The mesh is 2D (empty patches " << flatOutput(names) << ") but "
            << off << " of its " << returnReduce(mesh.nPoints(), sumOp<label>())
            << " points (counted on each rank that holds them) lie on no"
            << " empty patch: a 2D mesh is one cell thick between its empty"
            << " patches. Make the mesh one cell thick, or give these patches"
            << " another type (e.g. symmetryPlane) for a 3D morph"
            << exit(FatalError);
    }
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::solutionFrame::solutionFrame
(
    const polyMesh& mesh,
    const pointField& points0
)
:
    axisymmetric_(false),
    axis_(Zero),
    origin_(Zero)
{
    // The wedge planes (each patch's area-weighted normal and offset, on
    // all ranks; of points0: a restart reads a moved mesh)
    DynamicList<vector> normals;
    DynamicList<scalar> offsets;
    wordList names;
    for (const polyPatch& pp : mesh.boundaryMesh())
    {
        if (!isA<wedgePolyPatch>(pp))
        {
            continue;
        }
        vector area(Zero);
        scalar magArea = 0;
        vector moment(Zero);
        for (const face& f : pp)
        {
            const vector a = f.areaNormal(points0);
            area += a;
            magArea += mag(a);
            moment += mag(a)*f.centre(points0);
        }
        reduce(area, sumOp<vector>());
        reduce(magArea, sumOp<scalar>());
        reduce(moment, sumOp<vector>());
        if (magArea > 0)
        {
            const vector n = area/mag(area);
            normals.append(n);
            offsets.append(n & moment/magArea);
            names.append(pp.name());
        }
    }

    if (normals.empty())
    {
        const Vector<label>& solD = mesh.solutionD();
        for (direction d = 0; d < 3; ++d)
        {
            if (solD[d] == 1)
            {
                directions_.append(d);
            }
        }
        if (directions_.size() < 3)
        {
            checkOneCellThick(mesh);
        }
        return;
    }

    // The axis: where the two least parallel wedge planes meet
    label first = 0, second = 0;
    scalar most = 0;
    forAll(normals, i)
    {
        for (label j = i + 1; j < normals.size(); ++j)
        {
            const scalar s = mag(normals[i] ^ normals[j]);
            if (s > most)
            {
                most = s;
                first = i;
                second = j;
            }
        }
    }
    if (most < 1e-6)
    {
        FatalErrorInFunction
            << "The wedge patches " << flatOutput(names) << " lie in parallel"
            << " planes: an axisymmetric mesh needs two wedge planes that meet"
            << " at its axis (e.g. front and back, each a wedge patch)"
            << exit(FatalError);
    }
    const vector& n1 = normals[first];
    const vector& n2 = normals[second];
    const vector u = n1 ^ n2;
    const point onAxis =
        ((offsets[first]*n2 - offsets[second]*n1) ^ u)/magSqr(u);
    axis_ = canonical(u);
    origin_ = onAxis - (onAxis & axis_)*axis_;
    axisymmetric_ = true;

    // Each point's radial direction; the points within round-off of the
    // axis (of the mesh's size) have none
    const scalar onAxisTol = 1e-9*mesh.bounds().mag();
    radial_.setSize(points0.size());
    DynamicList<label> axisPoints;
    forAll(points0, pointi)
    {
        const vector rel = points0[pointi] - origin_;
        const vector r = rel - (rel & axis_)*axis_;
        const scalar magR = mag(r);
        if (magR > onAxisTol)
        {
            radial_[pointi] = r/magR;
        }
        else
        {
            radial_[pointi] = Zero;
            axisPoints.append(pointi);
        }
    }
    axisPoints_.transfer(axisPoints);

    // The front and back points of each meridian position: the ends of an
    // edge from one wedge patch to another, off the axis (a wedge cell's
    // edges across the wedge; each cell holding one holds both ends, so
    // every rank that holds a point holds its partner)
    labelList onWedge(mesh.nPoints(), -1);
    for (const polyPatch& pp : mesh.boundaryMesh())
    {
        if (isA<wedgePolyPatch>(pp))
        {
            UIndirectList<label>(onWedge, pp.meshPoints()) = pp.index();
        }
    }
    paired_.resize(mesh.nPoints());
    DynamicList<labelPair> pairs;
    for (const face& f : mesh.faces())
    {
        forAll(f, i)
        {
            const label p = f[i];
            const label q = f.nextLabel(i);
            if
            (
                onWedge[p] >= 0 && onWedge[q] >= 0 && onWedge[p] != onWedge[q]
             && !paired_.test(p) && radial_[p] != vector::zero
             && radial_[q] != vector::zero
            )
            {
                paired_.set(p);
                paired_.set(q);
                pairs.append(labelPair(min(p, q), max(p, q)));
            }
        }
    }
    meridianPairs_.transfer(pairs);
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

const char* Foam::solutionFrame::name() const
{
    return axisymmetric_ ? "2D axisymmetric" : (size() == 2 ? "2D" : "3D");
}


void Foam::solutionFrame::appendCoordinates
(
    const point& p0,
    std::vector<double>& x
) const
{
    if (axisymmetric_)
    {
        const vector rel = p0 - origin_;
        const scalar a = rel & axis_;
        x.push_back(a);
        x.push_back(mag(rel - a*axis_));
        return;
    }
    for (const label d : directions_)
    {
        x.push_back(p0[d]);
    }
}


void Foam::solutionFrame::constrain(vectorField& displacement) const
{
    if (axisymmetric_)
    {
        forAll(displacement, pointi)
        {
            displacement[pointi] = inFrame(pointi, displacement[pointi]);
        }
        return;
    }
    for (direction c = 0; c < 3; ++c)
    {
        if (!directions_.found(c))
        {
            displacement.replace(c, scalar(0));
        }
    }
}


Foam::vector Foam::solutionFrame::planeNormal
(
    const label pointi,
    const vector& n
) const
{
    if (!axisymmetric_)
    {
        return n;
    }
    const vector m = inFrame(pointi, n);
    const scalar magM = mag(m);
    return magM > 1e-6 ? m/magM : vector(Zero);
}


bool Foam::solutionFrame::mask
(
    const label pointi,
    const pointConstraint& pc,
    bool mask[3]
) const
{
    const label nd = size();
    const scalar tol = 1e-9;
    mask[0] = mask[1] = mask[2] = false;
    if (pc.first() == 0)
    {
        return true;
    }
    if (pc.first() == 3)
    {
        mask[0] = mask[1] = mask[2] = true;
        return true;
    }
    // plane: its normal, line: its free direction, in the frame
    vector b[3];
    basis(pointi, b);
    scalar v[3] = {0, 0, 0};
    scalar magV = 0;
    for (label k = 0; k < nd; ++k)
    {
        v[k] = b[k] & pc.second();
        magV += v[k]*v[k];
    }
    magV = std::sqrt(magV);
    if (magV < 1e-6)
    {
        // A plane across the frame holds nothing in it; a line across it
        // holds everything
        if (pc.first() == 2)
        {
            mask[0] = mask[1] = mask[2] = true;
        }
        return true;
    }
    for (label k = 0; k < nd; ++k)
    {
        if (mag(v[k]) >= (1 - tol)*magV)
        {
            for (label l = 0; l < nd; ++l)
            {
                mask[l] = (pc.first() == 1) == (l == k);
            }
            return true;
        }
    }
    return false;
}


// ************************************************************************* //
