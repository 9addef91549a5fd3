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
    interpolatingMotionSolver's settings: the keywords of <type>Coeffs that
    no one reads, dynamicMeshDict changed during a run, and the border of
    the solver's cellZone in dynamicMultiMotionSolverFvMesh.

\*---------------------------------------------------------------------------*/

#include "interpolatingMotionSolver.H"
#include "coeffsInput.H"
#include "boundaryConstraints.H"
#include "rigidLayers.H"
#include "syncTools.H"
#include "OStringStream.H"

// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::interpolatingMotionSolver::warnUnknownKeywords
(
    const wordList& known
) const
{
    const word coeffsName(type() + "Coeffs");
    const dictionary& dict = coeffDict();
    wordList all(known);
    all.append("invertedCells");
    all.append("rebase");
    all.append("curvedSlipAngle");
    all.append("rigidLayers");
    if (dict.dictName() == coeffsName)
    {
        coeffsInput::warnUnknown(dict, all);
        // The solver's entries beside its coefficients are not read (this
        // is the dictionary the solver is selected in; coeffDict() a copy)
        const dictionary& top = *this;
        for (const word& key : all)
        {
            if (top.found(key, keyType::LITERAL))
            {
                IOWarningInFunction(top)
                    << "Entry '" << key << "' beside " << coeffsName
                    << ": ignored (the solver reads its entries from "
                    << coeffsName << ")" << endl;
            }
        }
        return;
    }
    // Without <type>Coeffs the solver reads the dictionary it is selected in
    // (OpenFOAM's optionalSubDict): a misspelt <type>Coeffs would drop all of
    // its entries unread
    wordList others;
    for (const word& key : dict.toc())
    {
        if (dict.isDict(key) && !coeffsInput::nearest(key, {coeffsName}).empty())
        {
            FatalIOErrorInFunction(dict)
                << "No " << coeffsName << " sub-dictionary, but '" << key
                << "': did you mean " << coeffsName << "? (its entries would"
                << " be ignored)" << exit(FatalIOError);
        }
        if (key.size() > 6 && key.compare(key.size() - 6, 6, "Coeffs") == 0)
        {
            others.append(key);
        }
    }
    // (and what dynamicMotionSolverFvMesh reads there, and other solvers'
    // coefficients: a solver switched without its own runs with defaults)
    if (others.size())
    {
        IOWarningInFunction(dict)
            << "No " << coeffsName << ": " << type() << " reads its settings"
            << " from this dictionary itself (its defaults where it has none);"
            << " the other solvers' coefficients " << flatOutput(others)
            << " are not read" << endl;
    }
    all.append(wordList({"dynamicFvMesh", "motionSolverLibs", "motionSolver", "solver", "solvers"}));
    // (a zone's solver of dynamicMultiMotionSolverFvMesh: its zone, which
    // the mesh reads; a solver of the whole mesh moves it all, whatever
    // cellZone says)
    if (mesh().type() == "dynamicMultiMotionSolverFvMesh")
    {
        all.append("cellZone");
    }
    all.append(others);
    coeffsInput::warnUnknown(dict, all);
}


void Foam::interpolatingMotionSolver::findZoneBorder()
{
    // (dynamicMultiMotionSolverFvMesh gives this dictionary its zone; the
    // mesh stops when there is no such zone)
    const polyMesh& m = mesh();
    const dictionary& dict = *this;
    if (m.type() != "dynamicMultiMotionSolverFvMesh" || !dict.found("cellZone"))
    {
        return;
    }
    const label zonei = m.cellZones().findZoneID(dict.get<word>("cellZone"));
    if (zonei < 0)
    {
        return;
    }
    // Per point: 1 where a cell of the zone holds it, 2 where another does
    boolList inZone(m.nCells(), false);
    UIndirectList<bool>(inZone, m.cellZones()[zonei]) = true;
    labelList side(m.nPoints(), 0);
    forAll(m.cells(), celli)
    {
        for (const label facei : m.cells()[celli])
        {
            for (const label pointi : m.faces()[facei])
            {
                side[pointi] |= inZone[celli] ? 1 : 2;
            }
        }
    }
    syncTools::syncPointList(m, side, bitOrEqOp<label>(), label(0));
    DynamicList<label> border;
    forAll(side, pointi)
    {
        if (side[pointi] == 3)
        {
            border.append(pointi);
        }
    }
    zoneBorder_.transfer(border);
    checkZoneBorder_ = true;
}


void Foam::interpolatingMotionSolver::warnZoneBorder()
{
    checkZoneBorder_ = false;
    const boundaryConstraints& bc = *constraintsPtr_;
    bitSet rigid(mesh().nPoints());
    if (rigidLayersPtr_)
    {
        rigidLayersPtr_->markRigid(rigid);
    }
    label n = 0;
    for (const label pointi : zoneBorder_)
    {
        n += bc.owned()[pointi] && !bc.fixed()[pointi] && !rigid.test(pointi);
    }
    zoneBorder_.clear();
    reduce(n, sumOp<label>());
    if (n > 0)
    {
        const dictionary& dict = *this;
        WarningInFunction
            << type() << " (cellZone " << dict.get<word>("cellZone") << "): "
            << n << " points of the zone's cells are points of cells outside"
            << " it too, and neither its conditions nor rigidLayers move them."
            << " dynamicMultiMotionSolverFvMesh gives each of them the motion"
            << " of the last solver listed whose zone holds it: the cells"
            << " about them are not those this solver moved and checked"
            << " (invertedCells), and fold where the zones' motions there"
            << " differ. Where the other zone moves with a wall, list that wall"
            << " in rigidLayers with an innerDistance that takes in the"
            << " zone's border (its points then move with the wall)" << endl;
    }
}


bool Foam::interpolatingMotionSolver::read()
{
    OStringStream before;
    before<< coeffDict();
    if (!displacementMotionSolver::read())
    {
        return false;
    }
    OStringStream after;
    after<< coeffDict();
    if (after.str() != before.str())
    {
        WarningInFunction
            << type() << ": its settings in " << objectPath() << " changed at"
            << " time " << mesh().time().timeName() << ": they are read at the"
            << " start only; the run goes on with those it started with"
            << " (restart it to apply the new ones)" << endl;
    }
    return true;
}


// ************************************************************************* //
