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

#include "invertedCellCheck.H"
#include "sumsAndMaxima.H"
#include "vectorWidth.hpp"
#include "hugePageLists.H"

#include <string>
#include <unordered_map>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace Foam
{
namespace
{
    //- The faces of OpenFOAM's hex model, pointing out of the cell
    constexpr int hexFaces[6][4] =
    {
        {0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4},
        {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}
    };

    //- The screen of hexahedra, W at a time: each one's points (8 labels
    //  per cell, the model's order) and centre (their mean), its faces'
    //  pyramids against it (times six: twice the area, three times the
    //  volume); the cells whose smallest is at or under screenFraction of
    //  their mean are appended to candidates
    template<int W>
    inline __attribute__((always_inline)) void screenHexes
    (
        const labelList& hexPoints,
        const labelList& hexCells,
        const pointField& points,
        DynamicList<label>& candidates
    )
    {
        typedef typename mba::vec<W>::type vd;
        const label nHex = hexCells.size();
        const scalar fraction = invertedCellCheck::screenFraction/6;
        for (label c = 0; c < nHex; c += W)
        {
            vd x[8], y[8], z[8];
            for (int l = 0; l < W; ++l)
            {
                const label* h = &hexPoints[8*min(c + l, nHex - 1)];
                for (int v = 0; v < 8; ++v)
                {
                    const point& p = points[h[v]];
                    x[v][l] = p.x();
                    y[v][l] = p.y();
                    z[v][l] = p.z();
                }
            }
            vd cx = x[0], cy = y[0], cz = z[0];
            for (int v = 1; v < 8; ++v)
            {
                cx += x[v];
                cy += y[v];
                cz += z[v];
            }
            cx *= 0.125;
            cy *= 0.125;
            cz *= 0.125;
            vd sum = {}, smallest = {};
            for (int facei = 0; facei < 6; ++facei)
            {
                const int* f = hexFaces[facei];
                const vd ux = x[f[2]] - x[f[0]], uy = y[f[2]] - y[f[0]], uz = z[f[2]] - z[f[0]];
                const vd wx = x[f[3]] - x[f[1]], wy = y[f[3]] - y[f[1]], wz = z[f[3]] - z[f[1]];
                const vd mx = 0.25*(x[f[0]] + x[f[1]] + x[f[2]] + x[f[3]]) - cx;
                const vd my = 0.25*(y[f[0]] + y[f[1]] + y[f[2]] + y[f[3]]) - cy;
                const vd mz = 0.25*(z[f[0]] + z[f[1]] + z[f[2]] + z[f[3]]) - cz;
                const vd pyramid =
                    (uy*wz - uz*wy)*mx + (uz*wx - ux*wz)*my + (ux*wy - uy*wx)*mz;
                sum += pyramid;
                smallest = facei == 0 ? pyramid : (pyramid < smallest ? pyramid : smallest);
            }
            const vd threshold = fraction*sum;
            for (int l = 0; l < W && c + l < nHex; ++l)
            {
                if (!(smallest[l] > threshold[l]))
                {
                    candidates.append(hexCells[c + l]);
                }
            }
        }
    }

    void screenHexes2
    (
        const labelList& hexPoints,
        const labelList& hexCells,
        const pointField& points,
        DynamicList<label>& candidates
    )
    {
        screenHexes<2>(hexPoints, hexCells, points, candidates);
    }

    #ifdef MBA_WIDE_VECTORS
    MBA_WIDE_TARGET
    void screenHexes4
    (
        const labelList& hexPoints,
        const labelList& hexCells,
        const pointField& points,
        DynamicList<label>& candidates
    )
    {
        screenHexes<4>(hexPoints, hexCells, points, candidates);
    }
    #endif

    //- A face of the hex model as the set of its vertices (bit v: vertex v)
    constexpr int modelFace(const int m)
    {
        return 1 << hexFaces[m][0] | 1 << hexFaces[m][1]
             | 1 << hexFaces[m][2] | 1 << hexFaces[m][3];
    }

    //- A cell of 6 quadrilaterals on 8 points (its faces as positions among
    //  its points, outward) as a hexahedron: its 8 positions in the hex
    //  model's order, or false when its faces are not the model's
    bool hexOrder(const std::uint16_t f[6][4], int order[8])
    {
        // The first face is the model's (0 3 2 1); each of its points' edge
        // to a point off it (an edge of a face: two consecutive points) is
        // the model's vertical edge to 4, 5, 6, 7
        const int bottom[4] = {0, 3, 2, 1};
        for (int k = 0; k < 4; ++k) order[bottom[k]] = f[0][k];
        for (int k = 0; k < 4; ++k)
        {
            const int v = order[k];
            int up = -1;
            for (int i = 1; i < 6; ++i)
            {
                for (int j = 0; j < 4; ++j)
                {
                    if (f[i][j] != v) continue;
                    for (const int w : {f[i][(j + 1) % 4], f[i][(j + 3) % 4]})
                    {
                        if (w != f[0][0] && w != f[0][1] && w != f[0][2] && w != f[0][3])
                        {
                            if (up >= 0 && up != w) return false;
                            up = w;
                        }
                    }
                }
            }
            if (up < 0) return false;
            order[k + 4] = up;
        }
        // Every face of the cell is a face of the model (as a set of
        // points: bits of the model's vertices)
        int modelVertex[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
        for (int k = 0; k < 8; ++k)
        {
            if (order[k] > 7 || modelVertex[order[k]] >= 0) return false;
            modelVertex[order[k]] = k;
        }
        int matched = 0;
        for (int i = 0; i < 6; ++i)
        {
            int bits = 0;
            for (int j = 0; j < 4; ++j) bits |= 1 << modelVertex[f[i][j]];
            for (int m = 0; m < 6; ++m)
            {
                if (bits == modelFace(m)) matched |= 1 << m;
            }
        }
        return matched == 63;
    }

    //- The faces of each cell (cellFaces from faceStart[celli] to
    //  faceStart[celli + 1]), in cells() order (the owned ones, then the
    //  others, each ascending), without the mesh's cached cells()
    void cellFaceLists
    (
        const polyMesh& mesh,
        labelList& faceStart,
        labelList& cellFaces
    )
    {
        const labelList& own = mesh.faceOwner();
        const labelList& nei = mesh.faceNeighbour();
        const label nCells = mesh.nCells();
        faceStart.setSize(nCells + 1);
        faceStart = 0;
        for (const label celli : own) ++faceStart[celli + 1];
        for (const label celli : nei) ++faceStart[celli + 1];
        for (label celli = 0; celli < nCells; ++celli)
        {
            faceStart[celli + 1] += faceStart[celli];
        }
        cellFaces.setSize(faceStart.last());
        labelList fill(SubList<label>(faceStart, nCells));
        forAll(own, facei) cellFaces[fill[own[facei]]++] = facei;
        forAll(nei, facei) cellFaces[fill[nei[facei]]++] = facei;
    }

    //- A cell's points, each once, and its layout: the number of faces,
    //  then per face its number of points and their positions in points,
    //  turned to point out of the cell
    void cellLayout
    (
        const polyMesh& mesh,
        const label celli,
        const labelList& faceStart,
        const labelList& cellFaces,
        std::vector<label>& points,
        std::basic_string<std::uint16_t>& layout
    )
    {
        const faceList& faces = mesh.faces();
        const labelList& own = mesh.faceOwner();
        points.clear();
        layout.assign(1, std::uint16_t(faceStart[celli + 1] - faceStart[celli]));
        for (label i = faceStart[celli]; i < faceStart[celli + 1]; ++i)
        {
            const face& f = faces[cellFaces[i]];
            const bool owned = own[cellFaces[i]] == celli;
            layout.push_back(std::uint16_t(f.size()));
            forAll(f, k)
            {
                // (the neighbour's face reversed: the first point, the last, ...)
                const label pointi = owned || k == 0 ? f[k] : f[f.size() - k];
                label at = 0;
                while (at < label(points.size()) && points[at] != pointi) ++at;
                if (at == label(points.size())) points.push_back(pointi);
                if (at > 65535)
                {
                    FatalErrorInFunction
                        << "Cell " << celli << " has more than 65536 points"
                        << exit(FatalError);
                }
                layout.push_back(std::uint16_t(at));
            }
        }
    }

    //- A hexahedron's points in the hex model's order, or false when the
    //  cell is not one (the points in the order cellLayout would list them)
    bool hexCell
    (
        const polyMesh& mesh,
        const label celli,
        const labelList& faceStart,
        const labelList& cellFaces,
        label hexPoints[8]
    )
    {
        if (faceStart[celli + 1] - faceStart[celli] != 6) return false;
        const faceList& faces = mesh.faces();
        const labelList& own = mesh.faceOwner();
        label points[8];
        int nPoints = 0;
        std::uint16_t quads[6][4];
        for (int i = 0; i < 6; ++i)
        {
            const label facei = cellFaces[faceStart[celli] + i];
            const face& f = faces[facei];
            if (f.size() != 4) return false;
            const bool owned = own[facei] == celli;
            for (int k = 0; k < 4; ++k)
            {
                const label pointi = owned || k == 0 ? f[k] : f[4 - k];
                int at = 0;
                while (at < nPoints && points[at] != pointi) ++at;
                if (at == nPoints)
                {
                    if (nPoints == 8) return false;
                    points[nPoints++] = pointi;
                }
                quads[i][k] = std::uint16_t(at);
            }
        }
        int order[8];
        if (nPoints != 8 || !hexOrder(quads, order)) return false;
        for (int k = 0; k < 8; ++k) hexPoints[k] = points[order[k]];
        return true;
    }

    //- A face's centre and area as primitiveMesh::makeFaceCentresAndAreas
    //  makes them (the same operations in the same order)
    void checkMeshFaceGeometry
    (
        const face& f,
        const pointField& p,
        vector& centre,
        vector& area
    )
    {
        const label nPoints = f.size();
        if (nPoints == 3)
        {
            centre = (1.0/3.0)*(p[f[0]] + p[f[1]] + p[f[2]]);
            area = 0.5*((p[f[1]] - p[f[0]])^(p[f[2]] - p[f[0]]));
            return;
        }
        vector sumN = Zero;
        scalar sumA = 0.0;
        vector sumAc = Zero;
        vector fCentre = p[f[0]];
        for (label pi = 1; pi < nPoints; ++pi)
        {
            fCentre += p[f[pi]];
        }
        fCentre /= nPoints;
        for (label pi = 0; pi < nPoints; ++pi)
        {
            const label nextPi(pi == nPoints - 1 ? 0 : pi + 1);
            const vector nextPoint(p[f[nextPi]]);
            const vector thisPoint(p[f[pi]]);
            const vector c = thisPoint + nextPoint + fCentre;
            const vector n = (nextPoint - thisPoint)^(fCentre - thisPoint);
            const scalar a = mag(n);
            sumN += n;
            sumA += a;
            sumAc += a*c;
        }
        if (sumA < ROOTVSMALL)
        {
            centre = fCentre;
            area = Zero;
        }
        else
        {
            centre = (1.0/3.0)*sumAc/sumA;
            area = 0.5*sumN;
        }
    }
}
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::invertedCellCheck::invertedCellCheck
(
    const polyMesh& mesh,
    const bool hexKernel
)
:
    mesh_(mesh),
    maxCellPoints_(1)
{
    labelList faceStart, cellFaces;
    cellFaceLists(mesh, faceStart, cellFaces);

    // Each cell's points and layout: hexahedra in the model's order, the
    // other cells with their layouts (the same layouts shared)
    std::unordered_map<std::string, label> layoutIndex;
    std::basic_string<std::uint16_t> layout;
    std::vector<label> points;
    DynamicList<label> hexPoints(8*mesh.nCells());
    DynamicList<label> hexCells(mesh.nCells());
    adviseHugePages(hexPoints);
    adviseHugePages(hexCells);
    DynamicList<label> otherStart, otherPoints, otherCells, otherLayout;
    for (label celli = 0; celli < mesh.nCells(); ++celli)
    {
        label hex[8];
        if (hexKernel && hexCell(mesh, celli, faceStart, cellFaces, hex))
        {
            for (int k = 0; k < 8; ++k) hexPoints.append(hex[k]);
            hexCells.append(celli);
            continue;
        }
        cellLayout(mesh, celli, faceStart, cellFaces, points, layout);
        maxCellPoints_ = max(maxCellPoints_, label(points.size()));
        otherCells.append(celli);
        otherStart.append(otherPoints.size());
        for (const label pointi : points) otherPoints.append(pointi);
        const std::string key
        (
            reinterpret_cast<const char*>(layout.data()),
            layout.size()*sizeof(std::uint16_t)
        );
        const auto found = layoutIndex.find(key);
        if (found != layoutIndex.end())
        {
            otherLayout.append(found->second);
        }
        else
        {
            otherLayout.append(layoutStart_.size());
            layoutIndex.emplace(key, layoutStart_.size());
            layoutStart_.push_back(layouts_.size());
            layouts_.insert(layouts_.end(), layout.begin(), layout.end());
        }
    }
    otherStart.append(otherPoints.size());
    hexPoints_.transfer(hexPoints);
    hexCells_.transfer(hexCells);
    cellStart_.transfer(otherStart);
    cellPoints_.transfer(otherPoints);
    otherCells_.transfer(otherCells);
    cellLayout_.transfer(otherLayout);
    // (read at every check; a mesh of other cells than hexahedra shrank
    // them into new storage)
    onHugePages(hexPoints_);
    onHugePages(hexCells_);
    onHugePages(cellPoints_);
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

void Foam::invertedCellCheck::screenOtherCells
(
    const pointField& points,
    DynamicList<label>& candidates
) const
{
    // The other cells, their faces from their layouts
    List<point> p(maxCellPoints_);
    forAll(otherCells_, otheri)
    {
        const label* pointLabels = &cellPoints_[cellStart_[otheri]];
        const label nPoints = cellStart_[otheri + 1] - cellStart_[otheri];
        vector sum = Zero;
        for (label i = 0; i < nPoints; ++i)
        {
            p[i] = points[pointLabels[i]];
            sum += p[i];
        }
        const point centre = sum/nPoints;
        const std::uint16_t* layout = &layouts_[layoutStart_[cellLayout_[otheri]]];
        const label nFaces = *layout++;
        scalar pyramidSum = 0;
        scalar pyramidMin = GREAT;
        for (label facei = 0; facei < nFaces; ++facei)
        {
            const label size = *layout++;
            const point& p0 = p[layout[0]];
            vector area2;
            point mean;
            if (size == 4)
            {
                const point& p1 = p[layout[1]];
                const point& p2 = p[layout[2]];
                const point& p3 = p[layout[3]];
                mean = 0.25*(p0 + p1 + p2 + p3);
                area2 = (p2 - p0) ^ (p3 - p1);
            }
            else
            {
                // (the triangles about the first vertex: the same vector)
                vector faceSum = p0;
                area2 = Zero;
                for (label i = 1; i < size; ++i)
                {
                    faceSum += p[layout[i]];
                    if (i + 1 < size)
                    {
                        area2 += (p[layout[i]] - p0) ^ (p[layout[i + 1]] - p0);
                    }
                }
                mean = faceSum/size;
            }
            layout += size;
            const scalar pyramid = area2 & (mean - centre);
            pyramidSum += pyramid;
            pyramidMin = min(pyramidMin, pyramid);
        }
        if (!(pyramidMin > screenFraction*pyramidSum/nFaces))
        {
            candidates.append(otherCells_[otheri]);
        }
    }
}


Foam::invertedCellCheck::result
Foam::invertedCellCheck::check(const pointField& points) const
{
    // The screen, one pass over the cells: a cell's points, their mean, its
    // faces' pyramids against it (times six: twice the area, three times
    // the volume); a cell whose smallest pyramid is at or under
    // screenFraction of their mean (one of non-positive volume always is)
    // is judged by checkMesh's formulas. Hexahedra first, four at a time
    // where the core's kernels run on four doubles (mba::wideVectors: AVX2),
    // else two.
    DynamicList<label> candidates;
    #ifdef MBA_WIDE_VECTORS
    if (mba::wideVectors())
    {
        screenHexes4(hexPoints_, hexCells_, points, candidates);
    }
    else
    #endif
    {
        screenHexes2(hexPoints_, hexCells_, points, candidates);
    }
    screenOtherCells(points, candidates);

    result r;
    r.where = boundBox::invertedBox;
    DynamicList<label> invalid;
    for (const label celli : candidates)
    {
        ++r.nJudged;
        point centre;
        const label verdict = checkMeshVerdict(mesh_, points, celli, centre);
        if (verdict)
        {
            ++r.nInvalid;
            invalid.append(celli);
            (verdict == 1 ? r.nNonPositive : r.nFolded) += 1;
            // Where: the mean of the cell's points (the volume-weighted
            // centre of a cell whose volume is near zero lies anywhere)
            const labelList cellPoints =
                mesh_.cells()[celli].labels(mesh_.faces());
            point mean = Zero;
            for (const label pointi : cellPoints)
            {
                mean += points[pointi];
            }
            r.where.add(mean/cellPoints.size());
        }
    }
    r.cells.transfer(invalid);
    // The counts and the box over all ranks, in one reduction
    scalarList counts
    ({
        scalar(r.nInvalid), scalar(r.nNonPositive), scalar(r.nFolded), scalar(r.nJudged)
    });
    const point& lo = r.where.min();
    const point& hi = r.where.max();
    scalarList extents({-lo.x(), -lo.y(), -lo.z(), hi.x(), hi.y(), hi.z()});
    sumsAndMaxima(counts, extents);
    r.nInvalid = label(counts[0]);
    r.nNonPositive = label(counts[1]);
    r.nFolded = label(counts[2]);
    r.nJudged = label(counts[3]);
    r.where = boundBox
    (
        point(-extents[0], -extents[1], -extents[2]),
        point(extents[3], extents[4], extents[5])
    );
    return r;
}


Foam::scalar Foam::invertedCellCheck::checkMeshVolume
(
    const polyMesh& mesh,
    const pointField& points,
    const label celli,
    point& centre
)
{
    // primitiveMesh::makeCellCentresAndVols for one cell (its faces in
    // cells() order: the owned ones, then the others, each ascending, the
    // order in which OpenFOAM's loops over owners and neighbours add them)
    const labelList& cellFaces = mesh.cells()[celli];
    const labelList& own = mesh.faceOwner();
    const faceList& faces = mesh.faces();
    const label n = cellFaces.size();
    List<vector> fCtrs(n);
    List<vector> fAreas(n);
    vector cEst = Zero;
    forAll(cellFaces, i)
    {
        checkMeshFaceGeometry(faces[cellFaces[i]], points, fCtrs[i], fAreas[i]);
        cEst += fCtrs[i];
    }
    cEst /= n;
    vector ctr = Zero;
    scalar vol = 0;
    forAll(cellFaces, i)
    {
        const bool owned = own[cellFaces[i]] == celli;
        const scalar pyr3Vol =
            owned
          ? fAreas[i] & (fCtrs[i] - cEst)
          : fAreas[i] & (cEst - fCtrs[i]);
        ctr += pyr3Vol*((3.0/4.0)*fCtrs[i] + (1.0/4.0)*cEst);
        vol += pyr3Vol;
    }
    centre = mag(vol) > VSMALL ? ctr/vol : cEst;
    return vol*(1.0/3.0);
}


Foam::label Foam::invertedCellCheck::checkMeshVerdict
(
    const polyMesh& mesh,
    const pointField& points,
    const label celli,
    point& centre
)
{
    // checkMeshVolume, then checkCellVolumes and checkFacePyramids
    if (checkMeshVolume(mesh, points, celli, centre) < VSMALL)
    {
        return 1;
    }
    const labelList& own = mesh.faceOwner();
    const faceList& faces = mesh.faces();
    for (const label facei : mesh.cells()[celli])
    {
        // pyramidPointFaceRef(face, centre).mag(points), negated for the
        // owner: an error below -SMALL, as checkMesh's pyramids, or below
        // -turnedFraction of its own scale |S| |h| / 3 (a face turned
        // against the cell in a cell too small for the absolute SMALL:
        // checkMesh counts the face as a non-orthogonality error)
        const face& f = faces[facei];
        const vector S = f.areaNormal(points);
        const vector h = centre - f.centre(points);
        const scalar pyrVol = (1.0/3.0)*(own[facei] == celli ? -(S & h) : (S & h));
        if (pyrVol < -SMALL || pyrVol < -turnedFraction*(1.0/3.0)*mag(S)*mag(h))
        {
            return 2;
        }
    }
    return 0;
}



// ************************************************************************* //
