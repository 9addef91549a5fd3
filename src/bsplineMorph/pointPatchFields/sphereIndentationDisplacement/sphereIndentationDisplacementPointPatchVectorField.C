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

#include "sphereIndentationDisplacementPointPatchVectorField.H"
#include "pointPatchFields.H"
#include "transformField.H"
#include "addToRunTimeSelectionTable.H"

// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::sphereIndentationDisplacementPointPatchVectorField::readSphere
(
    const dictionary& dict
)
{
    centre_ = dict.get<point>("centre");
    radius_ = dict.get<scalar>("radius");
    if (!(radius_ > 0))
    {
        FatalIOErrorInFunction(dict)
            << "Entry 'radius' is " << radius_ << " on patch "
            << patch().name() << ": the sphere's radius must be > 0"
            << exit(FatalIOError);
    }
    direction_ = dict.get<vector>("direction");
    if (mag(direction_) < VSMALL)
    {
        FatalIOErrorInFunction(dict)
            << "direction " << direction_ << " of patch " << patch().name()
            << " is zero: give the direction the sphere is pressed in"
            << exit(FatalIOError);
    }
    direction_ /= mag(direction_);
    depth_ = Function1<scalar>::New("depth", dict);
}


void Foam::sphereIndentationDisplacementPointPatchVectorField::setDisplacement()
{
    const pointField& p0 = localPoints0();
    pointField p(transformPoints(motion().transformation(), p0));

    const scalar t = this->db().time().timeOutputValue();
    const point c = centre_ + depth_->value(t)*direction_;
    const scalar r2 = sqr(radius_);
    forAll(p, i)
    {
        const vector d = p[i] - c;
        const scalar s = d & direction_;
        const scalar lateral2 = magSqr(d - s*direction_);
        if (lateral2 < r2)
        {
            const scalar front = sqrt(r2 - lateral2);
            if (mag(s) < front)
            {
                p[i] += (front - s)*direction_;
            }
        }
    }
    fixedValuePointPatchVectorField::operator==(p - p0);
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::sphereIndentationDisplacementPointPatchVectorField::
sphereIndentationDisplacementPointPatchVectorField
(
    const pointPatch& p,
    const DimensionedField<vector, pointMesh>& iF
)
:
    solidBodyMotionDisplacementPointPatchVectorField(p, iF),
    centre_(Zero),
    radius_(1),
    direction_(0, 0, -1),
    depth_()
{}


Foam::sphereIndentationDisplacementPointPatchVectorField::
sphereIndentationDisplacementPointPatchVectorField
(
    const pointPatch& p,
    const DimensionedField<vector, pointMesh>& iF,
    const dictionary& dict
)
:
    solidBodyMotionDisplacementPointPatchVectorField(p, iF, dict)
{
    readSphere(dict);
    if (!dict.found("value"))
    {
        setDisplacement();
    }
}


Foam::sphereIndentationDisplacementPointPatchVectorField::
sphereIndentationDisplacementPointPatchVectorField
(
    const sphereIndentationDisplacementPointPatchVectorField& ptf,
    const pointPatch& p,
    const DimensionedField<vector, pointMesh>& iF,
    const pointPatchFieldMapper& mapper
)
:
    solidBodyMotionDisplacementPointPatchVectorField(ptf, p, iF, mapper),
    centre_(ptf.centre_),
    radius_(ptf.radius_),
    direction_(ptf.direction_),
    depth_(ptf.depth_.clone())
{
    setDisplacement();
}


Foam::sphereIndentationDisplacementPointPatchVectorField::
sphereIndentationDisplacementPointPatchVectorField
(
    const sphereIndentationDisplacementPointPatchVectorField& ptf
)
:
    solidBodyMotionDisplacementPointPatchVectorField(ptf),
    centre_(ptf.centre_),
    radius_(ptf.radius_),
    direction_(ptf.direction_),
    depth_(ptf.depth_.clone())
{}


Foam::sphereIndentationDisplacementPointPatchVectorField::
sphereIndentationDisplacementPointPatchVectorField
(
    const sphereIndentationDisplacementPointPatchVectorField& ptf,
    const DimensionedField<vector, pointMesh>& iF
)
:
    solidBodyMotionDisplacementPointPatchVectorField(ptf, iF),
    centre_(ptf.centre_),
    radius_(ptf.radius_),
    direction_(ptf.direction_),
    depth_(ptf.depth_.clone())
{
    setDisplacement();
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::sphereIndentationDisplacementPointPatchVectorField::updateCoeffs()
{
    if (this->updated())
    {
        return;
    }
    setDisplacement();
    fixedValuePointPatchVectorField::updateCoeffs();
}


void Foam::sphereIndentationDisplacementPointPatchVectorField::write
(
    Ostream& os
) const
{
    solidBodyMotionDisplacementPointPatchVectorField::write(os);
    os.writeEntry("centre", centre_);
    os.writeEntry("radius", radius_);
    os.writeEntry("direction", direction_);
    depth_->writeData(os);
}


// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

namespace Foam
{
    makePointPatchTypeField
    (
        pointPatchVectorField,
        sphereIndentationDisplacementPointPatchVectorField
    );
}

// ************************************************************************* //
