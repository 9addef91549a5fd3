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

#include "sumsAndMaxima.H"
#include "Pstream.H"

// * * * * * * * * * * * * * * * Global Functions  * * * * * * * * * * * * * //

void Foam::sumsAndMaxima(UList<scalar>& sums, UList<scalar>& maxima)
{
    if (!Pstream::parRun())
    {
        return;
    }
    const label nSums = sums.size();
    scalarList values(nSums + maxima.size());
    forAll(sums, i)
    {
        values[i] = sums[i];
    }
    forAll(maxima, i)
    {
        values[nSums + i] = maxima[i];
    }
    const auto combine = [nSums](scalarList& x, const scalarList& y)
    {
        forAll(x, i)
        {
            x[i] = i < nSums ? x[i] + y[i] : max(x[i], y[i]);
        }
    };
    Pstream::combineGather(values, combine);
    Pstream::combineScatter(values);
    forAll(sums, i)
    {
        sums[i] = values[i];
    }
    forAll(maxima, i)
    {
        maxima[i] = values[nSums + i];
    }
}


// ************************************************************************* //
