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
#include "PstreamCommunicator.H"
#include "Pstream.H"

// * * * * * * * * * * * * * * * Global Functions  * * * * * * * * * * * * * //

void Foam::sumsAndMaxima(UList<scalar>& sums, UList<scalar>& maxima)
{
    if (!Pstream::parRun())
    {
        return;
    }
    const label nSums = sums.size();
    const std::size_t n = nSums + maxima.size();
    std::vector<double> mine(n);
    std::copy(sums.begin(), sums.end(), mine.begin());
    std::copy(maxima.begin(), maxima.end(), mine.begin() + nSums);
    const std::vector<double> all = PstreamCommunicator().allGatherFixed(mine);
    forAll(sums, i)
    {
        sums[i] = 0;
    }
    for (std::size_t at = 0; at < all.size(); at += n)
    {
        forAll(sums, i)
        {
            sums[i] += all[at + i];
        }
        forAll(maxima, i)
        {
            maxima[i] = max(maxima[i], all[at + nSums + i]);
        }
    }
}


// ************************************************************************* //
