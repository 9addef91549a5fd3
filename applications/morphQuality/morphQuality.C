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

Application
    morphQuality

Group
    grpMeshManipulationUtilities

Description
    Compares a morphed mesh with its undeformed one (constant/polyMesh/points)
    at each selected time, prints the measures and writes them to
    postProcessing/morphQuality.dat (one row per selected time; the file is
    written anew by each run):

    - maxNonOrth     largest face non-orthogonality [deg]
    - maxSkewness    largest face skewness (checkMesh's measure)
    - minDeterminant smallest cell determinant (1 for a cube)
    - minVolRatio, maxVolRatio   cell volume / undeformed cell volume
    - nInvalid       invalid cells: non-positive volume, a face pyramid of the
                     wrong sign (checkMesh's face-pyramid error), a face with
                     non-orthogonality >= 90 deg or skewness > 4, or a
                     determinant < 0.001 (the checkMesh error thresholds)
    - boundary-layer preservation on the wall patches (-patches): for the
      cells on those faces (the first layer), the relative change of the
      layer height (cell volume / wall face area) and the change of the
      angle between the wall normal and the face-to-cell-centre direction
      [deg]: mean and worst (largest magnitude) of each.

    With -layers N (N > 0) the same two measures for each of the first N
    prism layers (those that the columns reach: fewer where the mesh ends
    first), printed as a table and written to
    postProcessing/morphQualityLayers.dat (a run without -layers removes
    it; one row per time and layer: time
    layer nCells meanHeightChange worstHeightChange meanAngleChange
    worstAngleChange). A column of layer cells starts at each wall face:
    layer 1 is its owner cell, and the face of a layer cell opposite to its
    bottom face (hex and prism cells) is the bottom face of the next layer's
    cell. The column stops at a cell without one opposite face (the
    polyhedra where snappyHexMesh's layers stop; the log says how many
    columns end below each layer) and at a boundary face, except processor
    and cyclic faces, across which it goes on (not across cyclicAMI). A
    layer cell's height is its volume / its bottom face's area, its angle
    the one between that face's normal (into the cell) and the
    face-to-cell-centre direction; layer 1 gives the
    first-layer measures above. A cell in two columns (near the corner of two
    walls) counts in each.

    Works in parallel (-parallel, on the decomposed case). The mesh topology
    must be the one in constant/polyMesh (a morph moves points only).

Usage
    \verbatim
    morphQuality [-patches '(sphere)'] [-layers N] [-time ... | -latestTime]
        [-parallel]
    \endverbatim
    -patches    wall patches for the boundary-layer measures (default: every
                patch of type wall)
    -layers     number of prism layers to measure one by one (default 0: the
                first-layer measures only, no morphQualityLayers.dat)

\*---------------------------------------------------------------------------*/

#include <algorithm>

#include "argList.H"
#include "timeSelector.H"
#include "Time.H"
#include "polyMesh.H"
#include "pointIOField.H"
#include "polyMeshTools.H"
#include "primitiveMeshTools.H"
#include "syncTools.H"
#include "wallPolyPatch.H"
#include "processorPolyPatch.H"
#include "cyclicPolyPatch.H"
#include "OFstream.H"
#include "OSspecific.H"
#include "pyramidPointFaceRef.H"
#include "unitConversion.H"
#include "IOmanip.H"

using namespace Foam;

namespace
{

struct layerGeometry
{
    scalarField height;     // cell volume / face area
    scalarField angle;      // wall normal vs face-to-centre [deg]
};

// The geometry of layer cells on their bottom faces (faces[i] of cells[i])
layerGeometry cellsOnFaces
(
    const polyMesh& mesh,
    const labelList& faces,
    const labelList& cells
)
{
    layerGeometry g;
    g.height.setSize(faces.size());
    g.angle.setSize(faces.size());
    const vectorField& Sf = mesh.faceAreas();
    const vectorField& Cf = mesh.faceCentres();
    const vectorField& C = mesh.cellCentres();
    const scalarField& V = mesh.cellVolumes();
    forAll(faces, i)
    {
        const label facei = faces[i];
        const label celli = cells[i];
        // the face normal into the cell (a wall face's cell is its owner)
        const vector inward =
            (mesh.faceOwner()[facei] == celli ? -Sf[facei] : Sf[facei])
           /(mag(Sf[facei]) + VSMALL);
        const vector d = C[celli] - Cf[facei];
        g.height[i] = V[celli]/(mag(Sf[facei]) + VSMALL);
        g.angle[i] = radToDeg(Foam::acos(min(1.0, max(-1.0, (d & inward)/(mag(d) + VSMALL)))));
    }
    return g;
}

// The first-layer cells' geometry on the given wall faces
layerGeometry firstLayer(const polyMesh& mesh, const labelList& faces)
{
    return cellsOnFaces(mesh, faces, labelList(UIndirectList<label>(mesh.faceOwner(), faces)));
}

// Prism layer k (0-based): the cells and their bottom faces on this rank
struct layerCells
{
    labelList faces;
    labelList cells;
};

// The face of cell c opposite its face f: the one face of the same size
// that shares no point with f (a hex's or prism's from that face), or -1.
// (cell::opposingFaceLabel's test, without its message on each polyhedron,
// as snappyHexMesh leaves where its layers stop)
label opposingFace(const cell& c, const label f, const faceList& faces)
{
    const face& bottom = faces[f];
    label found = -1;
    for (const label g : c)
    {
        const face& other = faces[g];
        if (g == f || other.size() != bottom.size())
        {
            continue;
        }
        const bool shares = std::any_of
        (
            other.begin(), other.end(),
            [&](const label pointi) { return bottom.found(pointi); }
        );
        if (!shares)
        {
            if (found >= 0)
            {
                return -1;
            }
            found = g;
        }
    }
    return found;
}

// The first nLayers layers of the columns on the wall faces (see the
// description). Layer by layer: a column leaving through a processor or
// cyclic face goes on in the cell on its other side, so each layer cell is on
// the rank that holds it, once per column.
List<layerCells> walkLayers
(
    const polyMesh& mesh,
    const labelList& wallFaces,
    const label nLayers
)
{
    const faceList& faces = mesh.faces();
    const cellList& cells = mesh.cells();
    const labelList& own = mesh.faceOwner();
    const labelList& nei = mesh.faceNeighbour();
    const polyBoundaryMesh& patches = mesh.boundaryMesh();
    const label nInternal = mesh.nInternalFaces();

    List<layerCells> layers(nLayers);
    if (nLayers <= 0) return layers;
    layers[0].faces = wallFaces;
    layers[0].cells = labelList(UIndirectList<label>(own, wallFaces));

    for (label k = 1; k < nLayers; ++k)
    {
        const layerCells& below = layers[k - 1];
        DynamicList<label> nextFaces(below.faces.size());
        DynamicList<label> nextCells(below.faces.size());
        // 1 on the processor and cyclic faces the columns leave through
        // (the coupled faces syncTools swaps: not cyclicAMI)
        labelList leaving(mesh.nBoundaryFaces(), 0);
        forAll(below.faces, i)
        {
            const label celli = below.cells[i];
            const label topi = opposingFace(cells[celli], below.faces[i], faces);
            if (topi < 0)
            {
                continue;   // not a hex or prism seen from this face
            }
            if (topi < nInternal)
            {
                nextFaces.append(topi);
                nextCells.append(own[topi] == celli ? nei[topi] : own[topi]);
            }
            else if
            (
                isA<processorPolyPatch>(patches[patches.whichPatch(topi)])
             || isA<cyclicPolyPatch>(patches[patches.whichPatch(topi)])
            )
            {
                leaving[topi - nInternal] = 1;
            }
        }
        // the other side's columns that enter here
        syncTools::swapBoundaryFaceList(mesh, leaving);
        forAll(leaving, bFacei)
        {
            if (leaving[bFacei])
            {
                nextFaces.append(nInternal + bFacei);
                nextCells.append(own[nInternal + bFacei]);
            }
        }
        layers[k].faces.transfer(nextFaces);
        layers[k].cells.transfer(nextCells);
    }
    return layers;
}

// The geometry of each layer's cells
List<layerGeometry> layersGeometry(const polyMesh& mesh, const List<layerCells>& layers)
{
    List<layerGeometry> g(layers.size());
    forAll(layers, k)
    {
        g[k] = cellsOnFaces(mesh, layers[k].faces, layers[k].cells);
    }
    return g;
}

// The face and cell measures checkMesh uses
struct measures
{
    scalarField ortho;      // face orthogonality (cos of non-orthogonality)
    scalarField skew;       // face skewness
    scalarField det;        // cell determinant

    explicit measures(const polyMesh& mesh)
    :
        ortho(polyMeshTools::faceOrthogonality(mesh, mesh.faceAreas(), mesh.cellCentres())),
        skew
        (
            polyMeshTools::faceSkewness
            (
                mesh, mesh.points(), mesh.faceCentres(), mesh.faceAreas(), mesh.cellCentres()
            )
        ),
        det
        (
            primitiveMeshTools::cellDeterminant
            (
                mesh,
                mesh.geometricD(),
                mesh.faceAreas(),
                syncTools::getInternalOrCoupledFaces(mesh)
            )
        )
    {}
};

// Cells failing the checkMesh error criteria (see the description)
labelHashSet invalidCells(const polyMesh& mesh, const measures& m)
{
    labelHashSet bad;
    const pointField& p = mesh.points();
    const vectorField& C = mesh.cellCentres();
    const scalarField& V = mesh.cellVolumes();
    const labelList& own = mesh.faceOwner();
    const labelList& nei = mesh.faceNeighbour();

    forAll(V, celli)
    {
        if (V[celli] <= 0) bad.insert(celli);
    }

    // Face pyramids from each cell's own centre
    scalarField ownPyr, neiPyr;
    primitiveMeshTools::facePyramidVolume(mesh, p, C, ownPyr, neiPyr);
    forAll(ownPyr, facei)
    {
        if (ownPyr[facei] <= 0) bad.insert(own[facei]);   // both positive when valid
    }
    forAll(neiPyr, facei)
    {
        if (neiPyr[facei] <= 0) bad.insert(nei[facei]);
    }

    // Face criteria: both cells of an internal face, the local cell of a
    // coupled one
    forAll(m.ortho, facei)
    {
        if (m.ortho[facei] <= 0 || m.skew[facei] > 4)
        {
            bad.insert(own[facei]);
            if (facei < mesh.nInternalFaces()) bad.insert(nei[facei]);
        }
    }
    forAll(m.det, celli)
    {
        if (m.det[celli] < 1e-3) bad.insert(celli);
    }
    return bad;
}

// mean of the magnitude and worst (largest magnitude) of a field over all
// ranks
void meanWorst(const scalarField& f, scalar& mean, scalar& worst)
{
    scalar sum = 0, hi = 0, lo = 0;
    for (const scalar v : f)
    {
        sum += mag(v);
        if (v > hi) hi = v;
        if (v < lo) lo = v;
    }
    const label n = returnReduce(f.size(), sumOp<label>());
    mean = returnReduce(sum, sumOp<scalar>())/max(n, 1);
    // the signed value of largest magnitude, from the largest and the
    // smallest value: independent of the order of the values and ranks (the
    // positive one of a tie)
    const scalar wMax = returnReduce(hi, maxOp<scalar>());
    const scalar wMin = returnReduce(lo, minOp<scalar>());
    worst = mag(wMax) >= mag(wMin) ? wMax : wMin;
}

} // End anonymous namespace


int main(int argc, char *argv[])
{
    argList::addNote
    (
        "Mesh quality of a morphed mesh against its undeformed one"
        " (constant/polyMesh/points), per selected time"
    );
    timeSelector::addOptions(false, false);
    argList::addOption
    (
        "patches",
        "wordRes",
        "Wall patches for the boundary-layer measures (default: all walls)"
    );
    argList::addOption
    (
        "layers",
        "N",
        "Measure the first N prism layers one by one (default 0: off)"
    );
    #include "setRootCase.H"
    #include "createTime.H"
    instantList timeDirs = timeSelector::select0(runTime, args);
    #include "createPolyMesh.H"

    // The wall faces
    const polyBoundaryMesh& patches = mesh.boundaryMesh();
    labelList wallPatches;
    if (args.found("patches"))
    {
        const wordRes names(args.getList<wordRe>("patches"));
        wallPatches = patches.patchSet(names).sortedToc();
        if (returnReduce(wallPatches.empty(), andOp<bool>()))
        {
            // (the case's patches: every rank's, without its processor patches)
            wordList caseNames(patches.nNonProcessor());
            forAll(caseNames, patchi)
            {
                caseNames[patchi] = patches[patchi].name();
            }
            FatalErrorInFunction
                << "-patches " << flatOutput(names) << " matches no patch; patches are "
                << flatOutput(caseNames) << exit(FatalError);
        }
    }
    else
    {
        forAll(patches, patchi)
        {
            if (isA<wallPolyPatch>(patches[patchi])) wallPatches.append(patchi);
        }
    }
    DynamicList<label> wallFaceList;
    wordList wallNames;
    for (const label patchi : wallPatches)
    {
        wallNames.append(patches[patchi].name());
        forAll(patches[patchi], i) wallFaceList.append(patches[patchi].start() + i);
    }
    const labelList wallFaces(wallFaceList);
    const label nLayers = args.getOrDefault<label>("layers", 0);
    if (nLayers < 0)
    {
        FatalErrorInFunction
            << "-layers " << nLayers << ": expected N >= 0" << exit(FatalError);
    }
    List<layerCells> layers(walkLayers(mesh, wallFaces, nLayers));
    // The columns end where the mesh does: the layers past the deepest cell
    // are not measured (they have no cells to compare). Columns that end
    // sooner (a cell with no single face opposite the one below) are said
    label above = -1;
    forAll(layers, k)
    {
        const label n = returnReduce(layers[k].cells.size(), sumOp<label>());
        if (n > 0 && k > 0 && n < above)
        {
            Info<< "-layers " << nLayers << ": " << above - n << " of the "
                << above << " columns on " << flatOutput(wallNames)
                << " end below layer " << k + 1 << " (a cell with no single"
                << " face opposite the one below: not a hex or prism seen"
                << " from it, or the mesh's boundary)" << nl << endl;
        }
        if (n == 0)
        {
            Info<< "-layers " << nLayers << ": the columns on "
                << flatOutput(wallNames) << " end after " << k
                << " layers; measuring those" << nl << endl;
            layers.setSize(k);
            break;
        }
        above = n;
    }

    // The undeformed mesh
    pointIOField points0
    (
        IOobject
        (
            "points",
            runTime.constant(),
            polyMesh::meshSubDir,
            mesh,
            IOobject::MUST_READ,
            IOobject::NO_WRITE,
            false
        )
    );
    mesh.movePoints(points0);
    const scalarField V0(mesh.cellVolumes());
    const layerGeometry layer0(firstLayer(mesh, wallFaces));
    const List<layerGeometry> layers0(layersGeometry(mesh, layers));

    Info<< "Undeformed mesh: " << returnReduce(mesh.nCells(), sumOp<label>())
        << " cells; boundary-layer measures on " << flatOutput(wallNames)
        << " (" << returnReduce(wallFaces.size(), sumOp<label>()) << " faces)" << nl << endl;

    autoPtr<OFstream> osPtr;
    if (Pstream::master())
    {
        const fileName dir(runTime.globalPath()/"postProcessing");
        mkDir(dir);
        osPtr.reset(new OFstream(dir/"morphQuality.dat"));
        osPtr()
            << "# morphQuality: against constant/polyMesh/points; boundary layer on "
            << flatOutput(wallNames) << nl
            << "# time maxNonOrth maxSkewness minDeterminant minVolRatio maxVolRatio nInvalid"
            << " meanLayerHeightChange worstLayerHeightChange meanLayerAngleChange worstLayerAngleChange"
            << nl;
    }
    autoPtr<OFstream> layersOsPtr;
    const fileName layersFile(runTime.globalPath()/"postProcessing"/"morphQualityLayers.dat");
    if (Pstream::master() && nLayers == 0 && isFile(layersFile))
    {
        // (a table of an earlier run with -layers would not match this one's)
        rm(layersFile);
        Info<< "Removed " << layersFile << " of an earlier run with -layers" << nl << endl;
    }
    if (Pstream::master() && nLayers > 0)
    {
        layersOsPtr.reset
        (
            new OFstream(layersFile)
        );
        layersOsPtr()
            << "# morphQuality -layers " << nLayers
            << ": against constant/polyMesh/points; prism layers on "
            << flatOutput(wallNames) << "; angles in deg" << nl
            << "# time layer nCells meanHeightChange worstHeightChange"
            << " meanAngleChange worstAngleChange" << nl;
    }

    forAll(timeDirs, timei)
    {
        runTime.setTime(timeDirs[timei], timei);
        // the time's points, or the undeformed ones where it has none
        const word instance
        (
            runTime.findInstance
            (
                polyMesh::meshSubDir, "points", IOobject::READ_IF_PRESENT
            )
        );
        if (instance == runTime.constant())
        {
            mesh.movePoints(points0);
        }
        else
        {
            mesh.movePoints
            (
                pointIOField
                (
                    IOobject
                    (
                        "points",
                        instance,
                        polyMesh::meshSubDir,
                        mesh,
                        IOobject::MUST_READ,
                        IOobject::NO_WRITE,
                        false
                    )
                )
            );
        }

        const measures m(mesh);
        const scalar maxNonOrth =
            radToDeg(Foam::acos(min(1.0, max(-1.0, gMin(m.ortho)))));
        const scalar maxSkew = gMax(m.skew);
        const scalar minDet = gMin(m.det);
        const scalarField ratio(mesh.cellVolumes()/V0);
        const scalar minRatio = gMin(ratio);
        const scalar maxRatio = gMax(ratio);
        const label nInvalid = returnReduce(invalidCells(mesh, m).size(), sumOp<label>());

        const layerGeometry layer(firstLayer(mesh, wallFaces));
        scalar hMean, hWorst, aMean, aWorst;
        meanWorst(layer.height/layer0.height - 1, hMean, hWorst);
        meanWorst(layer.angle - layer0.angle, aMean, aWorst);

        Info<< "Time = " << runTime.timeName() << nl
            << "    max non-orthogonality   " << maxNonOrth << " deg" << nl
            << "    max skewness            " << maxSkew << nl
            << "    min cell determinant    " << minDet << nl
            << "    cell volume / undeformed min " << minRatio << " max " << maxRatio << nl
            << "    invalid cells           " << nInvalid << nl
            << "    first-layer height change  mean " << hMean << " worst " << hWorst << nl
            << "    first-layer angle change   mean " << aMean << " deg, worst " << aWorst << " deg"
            << nl << endl;
        if (osPtr.valid())
        {
            osPtr()
                << runTime.timeName() << ' ' << maxNonOrth << ' ' << maxSkew << ' ' << minDet
                << ' ' << minRatio << ' ' << maxRatio << ' ' << nInvalid
                << ' ' << hMean << ' ' << hWorst << ' ' << aMean << ' ' << aWorst << nl;
        }

        // Each prism layer
        if (nLayers > 0)
        {
            Info<< "    prism layers" << nl
                << "    " << setw(5) << "layer" << ' ' << setw(7) << "nCells"
                << ' ' << setw(24) << "meanHeightChange" << ' ' << setw(24) << "worstHeightChange"
                << ' ' << setw(24) << "meanAngleChange" << ' ' << setw(24) << "worstAngleChange"
                << nl;
        }
        forAll(layers, k)
        {
            const layerGeometry g(cellsOnFaces(mesh, layers[k].faces, layers[k].cells));
            const label n = returnReduce(layers[k].cells.size(), sumOp<label>());
            meanWorst(g.height/layers0[k].height - 1, hMean, hWorst);
            meanWorst(g.angle - layers0[k].angle, aMean, aWorst);
            Info<< "    " << setw(5) << k + 1 << ' ' << setw(7) << n
                << ' ' << setw(24) << hMean << ' ' << setw(24) << hWorst
                << ' ' << setw(24) << aMean << ' ' << setw(24) << aWorst << nl;
            if (layersOsPtr.valid())
            {
                layersOsPtr()
                    << runTime.timeName() << ' ' << k + 1 << ' ' << n
                    << ' ' << hMean << ' ' << hWorst << ' ' << aMean << ' ' << aWorst << nl;
            }
        }
        if (nLayers > 0)
        {
            Info<< endl;
        }
    }

    if (osPtr.valid())
    {
        Info<< "Table: " << osPtr().name() << endl;
    }
    if (layersOsPtr.valid())
    {
        Info<< "Layers table: " << layersOsPtr().name() << endl;
    }
    Info<< "End\n" << endl;
    return 0;
}


// ************************************************************************* //
