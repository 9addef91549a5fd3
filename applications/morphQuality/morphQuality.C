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
    at each selected time, prints the measures and appends them to
    postProcessing/morphQuality.dat (one row per time):

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

    Works in parallel (-parallel, on the decomposed case). The mesh topology
    must be the one in constant/polyMesh (a morph moves points only).

Usage
    \verbatim
    morphQuality [-patches '(sphere)'] [-time ... | -latestTime] [-parallel]
    \endverbatim
    -patches    wall patches for the boundary-layer measures (default: every
                patch of type wall)

\*---------------------------------------------------------------------------*/

#include "argList.H"
#include "timeSelector.H"
#include "Time.H"
#include "polyMesh.H"
#include "pointIOField.H"
#include "polyMeshTools.H"
#include "primitiveMeshTools.H"
#include "syncTools.H"
#include "wallPolyPatch.H"
#include "OFstream.H"
#include "OSspecific.H"
#include "pyramidPointFaceRef.H"
#include "unitConversion.H"

using namespace Foam;

namespace
{

struct layerGeometry
{
    scalarField height;     // cell volume / face area
    scalarField angle;      // wall normal vs face-to-centre [deg]
};

// The first-layer cells' geometry on the given wall faces
layerGeometry firstLayer(const polyMesh& mesh, const labelList& faces)
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
        const label celli = mesh.faceOwner()[facei];
        const vector inward = -Sf[facei]/(mag(Sf[facei]) + VSMALL);
        const vector d = C[celli] - Cf[facei];
        g.height[i] = V[celli]/(mag(Sf[facei]) + VSMALL);
        g.angle[i] = radToDeg(Foam::acos(min(1.0, max(-1.0, (d & inward)/(mag(d) + VSMALL)))));
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

// mean and worst (largest magnitude) of a field over all ranks
void meanWorst(const scalarField& f, scalar& mean, scalar& worst)
{
    scalar sum = 0, w = 0;
    for (const scalar v : f)
    {
        sum += mag(v);
        if (mag(v) > mag(w)) w = v;
    }
    const label n = returnReduce(f.size(), sumOp<label>());
    mean = returnReduce(sum, sumOp<scalar>())/max(n, 1);
    // the signed value of largest magnitude
    const scalar wMax = returnReduce(w, maxOp<scalar>());
    const scalar wMin = returnReduce(w, minOp<scalar>());
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
            FatalErrorInFunction
                << "-patches " << flatOutput(names) << " matches no patch; patches are "
                << flatOutput(patches.names()) << exit(FatalError);
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
    }

    if (osPtr.valid())
    {
        Info<< "Table: " << osPtr().name() << endl;
    }
    Info<< "End\n" << endl;
    return 0;
}


// ************************************************************************* //
