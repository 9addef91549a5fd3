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

#include "rigidLayers.H"
#include "quaternion.H"

#include <cmath>

// The rigid layers' numerics, which know nothing of the mesh: the blend
// weight, the rotation of a fitted matrix (its polar factor), and a power of
// the walls' averaging in few sweeps (Chebyshev)

// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::scalar Foam::rigidLayers::weight
(
    const scalar d,
    const scalar inner,
    const scalar outer
)
{
    if (d <= inner)
    {
        return 1;
    }
    if (d >= outer)
    {
        return 0;
    }
    // (1 - s)^6 (1 + 6 s) of s = (d - inner)/(outer - inner): slope zero at
    // both ends (C1). The blend adds to the interpolated field w times the
    // gap between it and the rigid motion, which grows from zero at the
    // zone's outermost points about as s does: its strain along the normal
    // is d(s w)/ds times the two fields' difference in strain. That turns
    // from 1 at inner to at least -0.37 before outer (the quintic smoothstep:
    // -0.78): this weight falls fast while the gap is still small. Of the
    // family (1 - s)^k (1 + k s), k = 6 kept every cell of the twisted cube
    // at amplitude 1.5 from 50^3 to 100^3 cells, where k = 4 and the quintic
    // folded some, and turns a body in a far field as well as the quintic
    // (BENCHMARKS.md, "rigidLayers cost")
    const scalar s = (d - inner)/(outer - inner);
    const scalar r = 1 - s;
    const scalar r2 = r*r;
    return r2*r2*r2*(1 + 6*s);
}


Foam::scalar Foam::rigidLayers::pairShare
(
    const scalar d,
    const scalar d2,
    const scalar width
)
{
    const scalar t = min(max((d2 - d)/width, scalar(0)), scalar(1));
    const scalar r = 1 - t;
    const scalar dSqr = d*d;
    const scalar sum = dSqr + d2*d2;
    return sum > 0 ? r*r*(1 + 2*t)*dSqr/sum : 0.5;
}


Foam::tensor Foam::rigidLayers::twist(const tensor& R, const vector& n)
{
    const quaternion q(R);
    const quaternion t(q.w(), (q.v() & n)*n);
    const scalar m = mag(t);
    return m > SMALL ? quaternion(t.w()/m, t.v()/m).R() : tensor::I;
}


Foam::tensor Foam::rigidLayers::rotation(const tensor& M)
{
    // Newton's iteration for the polar decomposition, X <- (g X + X^-T/g)/2
    // with the determinant scaling g = |det X|^(-1/3) (Higham): quadratic
    // convergence to the orthogonal factor; M scaled to unit size first
    const scalar size = mag(M);
    if (!(size > 0))
    {
        return tensor::I;
    }
    // A symmetric positive definite M is its own positive factor: exactly
    // I (a wall at rest gives such an M bit for bit, and Newton's iteration
    // would leave values of 1e-80 off the diagonal for the fit to chase)
    if
    (
        M.xy() == M.yx() && M.xz() == M.zx() && M.yz() == M.zy()
     && M.xx() > 0 && M.xx()*M.yy() - M.xy()*M.yx() > 0 && det(M) > 0
    )
    {
        return tensor::I;
    }
    tensor X = M/size;
    if (!(det(X) > 1e-12))
    {
        return tensor::I;
    }
    for (label iter = 0; iter < 100; ++iter)
    {
        const scalar detX = det(X);     // (inv(X) is inv(X, det(X)))
        const scalar g = std::cbrt(1/detX);
        const tensor next = 0.5*(g*X + inv(X, detX).T()/g);
        const scalar change = mag(next - X);
        X = next;
        if (change < 1e-14)
        {
            break;
        }
    }
    // One more unscaled step: orthogonal to round-off
    return 0.5*(X + inv(X).T());
}


Foam::scalarList Foam::rigidLayers::powerCoeffs(const label n, const scalar tol)
{
    // With x = cos(t): ((1 + x)/2)^n = cos(t/2)^(2n)
    // = 4^-n (C(2n, n) + 2 sum_k C(2n, n - k) cos(k t)), and cos(k t) = T_k(x):
    // b_k = C(2n, n - k)/4^n, a binomial distribution over k = -n .. n
    scalarList b(n + 1);
    b[0] = std::exp(std::lgamma(2.0*n + 1) - 2*std::lgamma(n + 1.0) - n*std::log(4.0));
    for (label k = 1; k <= n; ++k)
    {
        b[k] = b[k - 1]*scalar(n - k + 1)/scalar(n + k);
    }
    // The weight of the terms above m, summed from the smallest
    scalarList above(n + 2, Zero);
    for (label k = n; k >= 0; --k)
    {
        above[k] = above[k + 1] + 2*b[k];
    }
    label m = 0;
    while (m < n && above[m + 1] > tol)
    {
        ++m;
    }
    scalarList a(m + 1);
    scalar sum = 0;
    for (label k = 0; k <= m; ++k)
    {
        a[k] = k ? 2*b[k] : b[0];
        sum += a[k];
    }
    for (scalar& ak : a)
    {
        ak /= sum;
    }
    return a;
}


Foam::label Foam::rigidLayers::nSweeps(const label n, const scalarList& coeffs)
{
    const label m = coeffs.size() - 1;
    return m >= 1 && m < n ? m : n;
}


void Foam::rigidLayers::power
(
    tensorField& v,
    const label n,
    const scalarList& coeffs,
    const sweepFunction& sweep,
    List<tensorField>& work
)
{
    const label m = nSweeps(n, coeffs);
    if (m == n)
    {
        for (label sweepi = 0; sweepi < n; ++sweepi)
        {
            sweep(v, v);
        }
        return;
    }
    // T_0 = v, T_1 = (2A - I) v, T_k+1 = 2 (2A - I) T_k - T_k-1: bounded by
    // v, since 2A - I has its eigenvalues in [-1, 1]; v <- sum a_k T_k
    work.setSize(3);
    tensorField& prev = work[0];
    tensorField& cur = work[1];
    tensorField& next = work[2];
    prev = v;
    sweep(prev, cur);
    forAll(v, i)
    {
        cur[i] = 2*cur[i] - prev[i];
        v[i] = coeffs[0]*prev[i] + coeffs[1]*cur[i];
    }
    for (label k = 2; k <= m; ++k)
    {
        sweep(cur, next);
        const scalar ak = coeffs[k];
        forAll(v, i)
        {
            next[i] = 4*next[i] - 2*cur[i] - prev[i];
            v[i] += ak*next[i];
        }
        prev.swap(cur);
        cur.swap(next);
    }
}


// ************************************************************************* //
