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

#include "coeffsInput.H"

#include <algorithm>
#include <cctype>
#include <vector>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    //- Edits (insert, delete, replace, swap neighbours) from a to b, letter
    //  case ignored
    std::size_t editDistance(const std::string& a, const std::string& b)
    {
        const std::size_t n = a.size(), m = b.size();
        std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
        for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
        for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
        const auto same = [](char x, char y) { return std::tolower(x) == std::tolower(y); };
        for (std::size_t i = 1; i <= n; ++i)
        {
            for (std::size_t j = 1; j <= m; ++j)
            {
                d[i][j] = std::min
                ({
                    d[i - 1][j] + 1,
                    d[i][j - 1] + 1,
                    d[i - 1][j - 1] + (same(a[i - 1], b[j - 1]) ? 0 : 1)
                });
                if
                (
                    i > 1 && j > 1 && same(a[i - 1], b[j - 2])
                 && same(a[i - 2], b[j - 1])
                )
                {
                    d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
                }
            }
        }
        return d[n][m];
    }
}


// * * * * * * * * * * * * * * * Global Functions  * * * * * * * * * * * * * //

Foam::word Foam::coeffsInput::nearest(const word& key, const wordList& known)
{
    word best;
    std::size_t fewest = std::string::npos;
    for (const word& k : known)
    {
        const std::size_t e = editDistance(key, k);
        if (e < fewest)
        {
            fewest = e;
            best = k;
        }
    }
    return fewest <= std::max<std::size_t>(1, best.size()/3) ? best : word::null;
}


void Foam::coeffsInput::warnUnknown
(
    const dictionary& dict,
    const wordList& known
)
{
    for (const word& key : dict.toc())
    {
        if (known.found(key))
        {
            continue;
        }
        const word near(nearest(key, known));
        OStringStream hint;
        if (!near.empty())
        {
            hint<< " (did you mean '" << near << "'?)";
        }
        OStringStream names;
        for (const word& k : known)
        {
            names<< ' ' << k;
        }
        IOWarningInFunction(dict)
            << "Unknown keyword '" << key << "' in " << dict.dictName()
            << hint.str().c_str() << ": ignored. Known keywords:"
            << names.str().c_str() << endl;
    }
}


void Foam::coeffsInput::checkDict
(
    const dictionary& dict,
    const word& key,
    const string& entries
)
{
    if (dict.found(key) && !dict.isDict(key))
    {
        FatalIOErrorInFunction(dict)
            << key << " must be a dictionary { " << entries.c_str() << " }"
            << exit(FatalIOError);
    }
}


void Foam::coeffsInput::warnUnread
(
    const dictionary& dict,
    const word& key,
    const word& entry,
    const word& readWith,
    const word& here
)
{
    if (readWith != here && dict.found(key))
    {
        IOWarningInFunction(dict)
            << key << " is read with " << entry << ' ' << readWith
            << " only, here " << here << ": ignored" << endl;
    }
}


// ************************************************************************* //
