/*---------------------------------------------------------------------------*\
    bsplineMorph: the numerics of rigidLayers: the blend's weight, the share
    of a foot on another wall, a rotation's twist about a normal, the fitted
    rotation, and the rotations' smoothing in few sweeps.
\*---------------------------------------------------------------------------*/

#include <catch2/catch.hpp>

#include "rigidLayers.H"
#include "quaternion.H"
#include "transform.H"

#include <random>

using namespace Foam;

TEST_CASE("rigidLayers: the blend weight is 1 inside, 0 outside, C1 between, and strains the blend little", "[foam][rigidLayers]")
{
    const scalar inner = 0.1, outer = 0.4;
    const auto w = [&](const scalar d) { return rigidLayers::weight(d, inner, outer); };
    CHECK(w(0) == 1);
    CHECK(w(inner) == 1);
    CHECK(w(outer) == 0);
    CHECK(w(1) == 0);
    // (1 - s)^6 (1 + 6 s) at s = 1/2
    CHECK(w(0.5*(inner + outer)) == Approx(1.0/16).margin(1e-15));
    // Monotone, and value and slope continuous at both ends: the one-sided
    // slopes there are far below the blend's inside (at least 2/(outer -
    // inner) at s = 1/4)
    scalar last = 1;
    for (label i = 0; i <= 1000; ++i)
    {
        const scalar v = w(inner + (outer - inner)*i/1000.0);
        REQUIRE(v <= last);
        last = v;
    }
    CHECK((w(inner + 0.24*(outer - inner)) - w(inner + 0.26*(outer - inner)))/(0.02*(outer - inner)) > 2/(outer - inner));
    for (const scalar end : {inner, outer})
    {
        const scalar side = end == inner ? 1 : -1;
        const scalar h = 1e-4*(outer - inner);
        const scalar slope = (w(end + side*h) - w(end))/h;
        CHECK(std::abs(slope) < 1e-2/(outer - inner));
    }
    // The blend w rigid + (1 - w) interpolated, with the two fields apart by
    // a gap growing as s from the zone's edge, strains along the normal by
    // d(s w)/ds times their difference in strain: from 1 at inner it may
    // undershoot 0 before outer, by at most 0.37 (the quintic smoothstep:
    // 0.78, folding cells under the twisted cube's crease)
    scalar least = 1;
    const label n = 100000;
    for (label i = 0; i < n; ++i)
    {
        const scalar s0 = scalar(i)/n, s1 = scalar(i + 1)/n;
        const scalar d0 = inner + s0*(outer - inner), d1 = inner + s1*(outer - inner);
        least = min(least, (s1*w(d1) - s0*w(d0))*n);
    }
    CHECK(least > -0.375);
    CHECK(least < -0.365);
}


TEST_CASE("rigidLayers: a foot on another wall gets half on the bisector, none on the nearest wall or beyond the width", "[foam][rigidLayers]")
{
    const scalar width = 0.12;
    const auto a = [&](const scalar d, const scalar d2) { return rigidLayers::pairShare(d, d2, width); };
    CHECK(a(0.05, 0.05) == Approx(0.5).epsilon(1e-15));
    CHECK(a(0, 0) == 0.5);
    CHECK(a(0, 0.01) == 0);
    CHECK(a(0.05, 0.05 + width) == Approx(0).margin(1e-15));
    CHECK(a(0.05, 0.2) == 0);
    // (1 - t)^2 (1 + 2 t) d^2/(d^2 + d2^2) at t = 1/2: 1/2 of 0.05^2/(0.05^2 + 0.11^2)
    CHECK(a(0.05, 0.11) == Approx(0.5*0.0025/(0.0025 + 0.0121)).epsilon(1e-14));
    // Falling from the bisector, and Lipschitz (steps of 1e-6 change it by
    // at most 1.1e-5: its steepest slope is -1/(2 d), on the bisector)
    scalar last = 0.5;
    for (label i = 1; i <= 120000; ++i)
    {
        const scalar v = a(0.05, 0.05 + i*1e-6);
        REQUIRE(v <= last);
        REQUIRE(last - v < 1.1e-5);
        last = v;
    }
    CHECK(last == Approx(0).margin(1e-15));
}


TEST_CASE("rigidLayers: a rotation's twist about a normal is its turn about it", "[foam][rigidLayers]")
{
    const vector n = normalised(vector(0.3, -0.2, 1));
    const vector m = normalised(n ^ vector(1, 0, 0));
    const tensor Rn = Ra(n, 0.8);
    const tensor Rm = Ra(m, 0.5);
    // (the swing about m applied after the turn about n: the twist is the
    // turn; a swing alone has none; a wall at rest stays exactly at rest)
    CHECK(mag(rigidLayers::twist(Rn, n) - Rn) < 1e-15);
    CHECK(mag(rigidLayers::twist(Rm & Rn, n) - Rn) < 1e-15);
    CHECK(mag(rigidLayers::twist(Rm, n) - tensor::I) < 1e-15);
    CHECK(rigidLayers::twist(tensor::I, n) == tensor::I);
    // A swing of half a turn about m leaves no twist to find: the identity
    CHECK(rigidLayers::twist(Ra(m, constant::mathematical::pi), n) == tensor::I);
}


TEST_CASE("rigidLayers: the fitted rotation is the rotation of a rigid map", "[foam][rigidLayers]")
{
    // M = R S with S symmetric positive definite: the polar factor is R
    const quaternion q(vector(1, -2, 0.5)/mag(vector(1, -2, 0.5)), 0.9);
    const tensor R = q.R();
    const tensor S(2, 0.3, 0.1, 0.3, 1, -0.2, 0.1, -0.2, 0.5);
    const tensor Q = rigidLayers::rotation(R & S);
    CHECK(mag(Q - R) < 1e-14);
    CHECK(mag(rigidLayers::rotation(1e-9*S) - tensor::I) < 1e-14);
    // S itself (a wall at rest) exactly: no round-off for the fit to chase;
    // a symmetric map that is no such S (a half turn) keeps its rotation
    CHECK(rigidLayers::rotation(S) == tensor::I);
    const tensor halfTurn(-2, 0, 0, 0, -1, 0, 0, 0, 0.5);
    CHECK(mag(rigidLayers::rotation(halfTurn) - tensor(-1, 0, 0, 0, -1, 0, 0, 0, 1)) < 1e-14);
    // Flat S (a plane of edges and its normal, as on a wall face) too
    const tensor flat(1, 0, 0, 0, 1, 0, 0, 0, 1e-3);
    CHECK(mag(rigidLayers::rotation(R & flat) - R) < 1e-13);
    // A mirror or a singular map has no rotation: identity
    CHECK(rigidLayers::rotation(tensor(-1, 0, 0, 0, 1, 0, 0, 0, 1)) == tensor::I);
    CHECK(rigidLayers::rotation(tensor::zero) == tensor::I);
}


TEST_CASE("rigidLayers: the rotations' smoothing takes n averagings in about 5 sqrt(n) sweeps", "[foam][rigidLayers]")
{
    // The coefficients: ((1 + x)/2)^n to 1e-12 on [-1, 1], fewer than n
    // terms from n = 21 on, summing to 1 (constants kept)
    for (const label n : {1, 20, 21, 37, 145, 400})
    {
        const scalarList a = rigidLayers::powerCoeffs(n, 1e-12);
        scalar sum = 0, worst = 0;
        for (const scalar ak : a)
        {
            sum += ak;
        }
        for (label i = 0; i <= 200; ++i)
        {
            const scalar x = -1 + i/100.0;
            scalar p = 0;
            forAll(a, k)
            {
                p += a[k]*std::cos(k*std::acos(x));
            }
            worst = max(worst, std::abs(p - std::pow((1 + x)/2, n)));
        }
        INFO("n = " << n << ": " << a.size() - 1 << " sweeps");
        CHECK(std::abs(sum - 1) < 1e-15);
        CHECK(worst < 2e-12);
        CHECK(a.size() - 1 <= (n < 21 ? n : label(std::ceil(5.1*std::sqrt(scalar(n))))));
        CHECK((n < 21 || a.size() - 1 < n));
    }
    CHECK(rigidLayers::powerCoeffs(145, 1e-12).size() - 1 == 60);

    // The averaging of a wall: each face's mean of its points, then each
    // point's mean of its faces; here a chain of edges with a triangle at
    // every third point, and seeded random tensors
    const label nPoints = 300;
    std::vector<std::vector<label>> faces;
    for (label i = 0; i + 1 < nPoints; ++i)
    {
        faces.push_back({i, i + 1});
        if (i % 3 == 0 && i + 2 < nPoints)
        {
            faces.push_back({i, i + 1, i + 2});
        }
    }
    label nSweeps = 0;
    const rigidLayers::sweepFunction sweep = [&](const tensorField& in, tensorField& out)
    {
        ++nSweeps;
        tensorField sum(nPoints, Zero);
        scalarField count(nPoints, Zero);
        for (const auto& f : faces)
        {
            tensor mean(Zero);
            for (const label p : f)
            {
                mean += in[p]/scalar(f.size());
            }
            for (const label p : f)
            {
                sum[p] += mean;
                count[p] += 1;
            }
        }
        out.setSize(nPoints);
        forAll(out, p)
        {
            out[p] = sum[p]/count[p];
        }
    };
    std::mt19937 random(2026);
    std::uniform_real_distribution<scalar> uniform(-1, 1);
    tensorField v0(nPoints);
    for (tensor& t : v0)
    {
        for (direction c = 0; c < tensor::nComponents; ++c)
        {
            t[c] = uniform(random);
        }
    }
    for (const label n : {10, 37, 145})
    {
        tensorField plain(v0), fast(v0);
        List<tensorField> work;
        nSweeps = 0;
        rigidLayers::power(plain, n, scalarList(), sweep, work);
        CHECK(nSweeps == n);
        const scalarList a = rigidLayers::powerCoeffs(n, 1e-12);
        nSweeps = 0;
        rigidLayers::power(fast, n, a, sweep, work);
        INFO("n = " << n << ": " << nSweeps << " sweeps");
        CHECK(nSweeps == min(n, label(a.size() - 1)));
        // The same smoothing (which changes the field by far more)
        CHECK(max(mag(fast - plain)) < 1e-12);
        CHECK(max(mag(plain - v0)) > 0.5);
    }
}
