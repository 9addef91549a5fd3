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

#include "multilevelBSplineMotionSolver.H"
#include "coeffsInput.H"
#include "sumsAndMaxima.H"
#include "addToRunTimeSelectionTable.H"
#include "OStringStream.H"
#include "Enum.H"
#include "clockTime.H"
#include "thinPlateTrend.hpp"

#include <algorithm>
#include <cstdio>

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

namespace Foam
{
    defineTypeNameAndDebug(multilevelBSplineMotionSolver, 0);

    addToRunTimeSelectionTable
    (
        motionSolver,
        multilevelBSplineMotionSolver,
        dictionary
    );

    addToRunTimeSelectionTable
    (
        displacementMotionSolver,
        multilevelBSplineMotionSolver,
        displacement
    );

    namespace
    {
        enum class initialApproximation { affine, none, thinPlateSpline };
        const Enum<initialApproximation> initialApproximationNames
        ({
            { initialApproximation::affine, "affine" },
            { initialApproximation::none, "none" },
            { initialApproximation::thinPlateSpline, "thinPlateSpline" },
        });

        const Enum<mba::params::exchangeMode> exchangeNames
        ({
            { mba::params::exchangeMode::automatic, "automatic" },
            { mba::params::exchangeMode::direct, "direct" },
            { mba::params::exchangeMode::chunked, "chunked" },
            { mba::params::exchangeMode::tree, "tree" },
        });

        //- The control points of bc (points0 in the solution directions,
        //  packed)
        std::vector<double> controlCoordinates
        (
            const boundaryConstraints& bc,
            const pointField& points0
        )
        {
            std::vector<double> xyz;
            xyz.reserve(bc.frame().size()*bc.controlPoints().size());
            for (const label pointi : bc.controlPoints())
            {
                bc.frame().appendCoordinates(points0[pointi], xyz);
            }
            return xyz;
        }

        //- A multilevel B-spline plan in D dimensions: its control points'
        //  coordinates (which the plan views) and the plan
        template<int D>
        class bsplineInterpolator
        :
            public boundaryInterpolator
        {
            //- The control points' coordinates (declared before plan_,
            //  which views them)
            const std::vector<double> controlXyz_;

            mba::multilevel<D> plan_;

            //- initialApproximation thinPlateSpline: the spline (else
            //  null), the level whose nodes sample it and the samples
            std::unique_ptr<rbf::thinPlateTrend<D>> trend_;
            const int trendLevel_;
            std::vector<double> trendValues_;

            //- Whether a fit that stopped above its threshold was reported
            //  (the solver's flag: once a run)
            bool& warned_;

        public:

            //- evalRead: per evaluation point x direction, whether the
            //  solver reads its value (params.stopUnread); trendGrid: the
            //  thin-plate spline's grid (0: none), sampled at the nodes of
            //  level trendLevel
            bsplineInterpolator
            (
                const mba::communicator& comm,
                const mba::params& params,
                const boundaryConstraints& bc,
                const pointField& points0,
                const double* evalXyz,
                const std::size_t nEval,
                std::vector<std::uint8_t> evalRead,
                const label trendGrid,
                const label trendLevel,
                bool& warned
            )
            :
                controlXyz_(controlCoordinates(bc, points0)),
                plan_
                (
                    comm, params, D,
                    mba::pointsView<D>(controlXyz_.data(), bc.controlPoints().size()),
                    bc.mask(), mba::pointsView<D>(evalXyz, nEval), std::move(evalRead)
                ),
                trendLevel_(trendGrid > 0 ? trendLevel : -1),
                warned_(warned)
            {
                if (trendGrid > 0)
                {
                    const std::vector<double> nodes = plan_.latticeNodes(trendLevel);
                    // (the grid over the lattice domain, which every rank shares)
                    const mba::domain<D>& dom = plan_.dom();
                    mba::box<D> b;
                    for (int d = 0; d < D; ++d)
                    {
                        b.lo[d] = dom.lo[d];
                        b.hi[d] = dom.lo[d] + dom.n0[d]*dom.h0;
                    }
                    trend_.reset
                    (
                        new rbf::thinPlateTrend<D>
                        (
                            comm, D,
                            mba::pointsView<D>(controlXyz_.data(), bc.controlPoints().size()),
                            bc.mask(), bc.addedControls(), b, trendGrid,
                            mba::pointsView<D>(nodes.data(), nodes.size()/D)
                        )
                    );
                    Info<< multilevelBSplineMotionSolver::typeName
                        << ": thinPlateSpline through " << trend_->centres()
                        << " centres (grid " << trendGrid << ", "
                        << trend_->systems() << " system"
                        << (trend_->systems() == 1 ? "" : "s")
                        << "), sampled at the " << nodes.size()/D
                        << " nodes of level " << trendLevel << endl;
                }
            }

            //- Fit the control values, evaluate at the evaluation points
            virtual interpolationReport interpolate
            (
                const boundaryConstraints& bc,
                std::vector<double>& values
            );
        };
    }
}


// * * * * * * * * * * * * * Local Member Functions  * * * * * * * * * * * * //

template<int D>
Foam::interpolationReport Foam::bsplineInterpolator<D>::interpolate
(
    const boundaryConstraints& bc,
    std::vector<double>& values
)
{
    scalar evalSeconds = 0, trendSeconds = 0;
    try
    {
        if (trend_)
        {
            const clockTime timer;
            trend_->sample(bc.values(), trendValues_);
            trendSeconds = timer.elapsedTime();
        }
        plan_.fit(bc.values(), trendLevel_, trendValues_);
        const clockTime timer;
        plan_.evaluate(values);
        evalSeconds = timer.elapsedTime();
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "Multilevel B-spline fit failed: " << e.what() << exit(FatalError);
    }

    const mba::fitReport& r = plan_.report();
    const word& type = multilevelBSplineMotionSolver::typeName;
    // (residuals under 1e-12 of the lattice domain's longest edge are
    // round-off)
    const mba::domain<D>& dom = plan_.dom();
    const scalar domainSize =
        dom.h0*scalar(*std::max_element(dom.n0.begin(), dom.n0.end()));
    if
    (
        !r.converged && !r.unread && !warned_
     && r.maxResidual > 1e-12*domainSize
    )
    {
        // (once: the step's log line says it every time)
        warned_ = true;
        WarningInFunction
            << type << ": the fit stopped after " << r.levels << " levels with"
            << " a max residual of " << r.maxResidual << ", above its threshold "
            << r.threshold << " (tolerance): the prescribed points still take"
            << " their values exactly, the interpolated ones may be off by about"
            << " that much. More levels reach it (maxLevels, at most 30; the log"
            << " line says 'not reached' while they do not)" << endl;
    }
    double nodes = 0, bytes = 0, messages = 0;
    label separated = 0, chunked = 0, tree = 0;
    for (const mba::levelStats& s : plan_.stats())
    {
        if (s.level < r.levels)
        {
            separated += s.separated;
            chunked += s.chunked;
            tree += s.tree;
            nodes += s.nodes;
            bytes += s.bytesReceivedPerApply;
            messages += s.messagesReceived;
            if (multilevelBSplineMotionSolver::debug)
            {
                Pout<< type << ": level " << s.level << " h " << s.h << " nodes " << s.nodes
                    << " tiles own/view " << s.ownTiles << '/' << s.viewTiles
                    << (s.dense ? " dense" : " sparse") << (s.separated ? " separated" : "")
                    << (s.chunked ? " chunked" : "") << (s.tree ? " tree" : "")
                    << " lone points " << s.lonePoints << ", " << s.bytes/1048576.0 << " MB"
                    << " received " << s.bytesReceivedPerApply
                    << " B, max residual " << s.maxResidual << ", " << s.seconds << " s (plan "
                    << s.planSeconds << " s)" << endl;
            }
        }
    }
    // (the six figures in one reduction)
    scalarList sums({nodes, bytes, messages, scalar(plan_.bytes())});
    scalarList maxima({bytes, messages});
    sumsAndMaxima(sums, maxima);
    nodes = sums[0];
    bytes = sums[1];
    messages = sums[2];
    const scalar planMB = sums[3]/1048576;
    const scalar bytesMax = maxima[0];
    const scalar messagesMax = maxima[1];
    OStringStream os;
    os  << r.levels << " levels (" << separated << " separated";
    if (Pstream::parRun())
    {
        os  << ", " << chunked << " chunked";
        if (tree)
        {
            os  << ", " << tree << " tree";
        }
    }
    const char* reached =
        r.converged ? ""
      : r.unread ? ", not needed: no finer level reaches an interpolated point"
      : ", not reached";
    os  << "), max residual " << r.maxResidual
        << " (threshold " << r.threshold << reached
        << "), " << label(nodes) << " lattice nodes, plan " << planMB << " MB, "
        << label(bytes) << " bytes exchanged (" << label(bytesMax) << " by one rank) in "
        << label(messages) << " messages (" << label(messagesMax) << " by one rank), ";
    if (trend_)
    {
        os  << "thin-plate spline " << trendSeconds << " s, ";
    }
    os  << "fit " << r.seconds << " s, evaluation " << evalSeconds << " s";
    interpolationReport report;
    report.summary = os.str();
    report.add("levels", r.levels);
    report.add("separatedLevels", separated);
    report.add("chunkedLevels", chunked);
    report.add("treeLevels", tree);
    report.add("maxResidual", r.maxResidual);
    report.add("threshold", r.threshold);
    report.add("converged", r.converged);
    report.add("unread", r.unread);
    report.add("latticeNodes", nodes);
    report.add("planMB", planMB);
    report.add("bytes", bytes);
    report.add("bytesOneRank", bytesMax);
    report.add("messages", messages);
    report.add("messagesOneRank", messagesMax);
    if (trend_)
    {
        report.add("thinPlateSpline_s", trendSeconds);
    }
    report.add("fit_s", r.seconds);
    report.add("evaluation_s", evalSeconds);
    return report;
}


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::multilevelBSplineMotionSolver::readCoeffs()
{
    const dictionary& dict = coeffDict();

    params_.tolerance = coeffsInput::getInRange<scalar>(dict, "tolerance", 1e-6, 0);
    params_.relative = dict.lookupOrDefault<bool>("relativeTolerance", true);
    params_.maxLevels = coeffsInput::getInRange<label>(dict, "maxLevels", 12, 1, 30);
    params_.initialGrid =
        coeffsInput::getInRange<label>(dict, "initialGrid", 1, 1, 1 << 20);
    const initialApproximation start = coeffsInput::getEnum
    (
        dict, "initialApproximation", initialApproximationNames,
        initialApproximation::affine
    );
    // (the thin-plate spline's linear polynomial holds the affine part; the
    // affine start then fits what the sampled spline leaves)
    params_.affine = start != initialApproximation::none;
    trendGrid_ = 0;
    coeffsInput::checkDict(dict, "thinPlateSplineCoeffs", "grid ...; level ...;");
    if (start == initialApproximation::thinPlateSpline)
    {
        // (its entries only: none falls back to the enclosing dictionary)
        const dictionary tps(dict.subOrEmptyDict("thinPlateSplineCoeffs"));
        trendGrid_ = coeffsInput::getInRange<label>(tps, "grid", 8, 1, 32);
        trendLevel_ = coeffsInput::getInRange<label>(tps, "level", 4, 0, 5);
        coeffsInput::warnUnknown(tps, {"grid", "level"});
    }
    coeffsInput::warnUnread
    (
        dict, "thinPlateSplineCoeffs", "initialApproximation",
        initialApproximationNames[initialApproximation::thinPlateSpline],
        initialApproximationNames[start]
    );
    params_.bucketTiles = coeffsInput::getInRange<label>(dict, "bucketTiles", 32, 1);
    params_.exchange = coeffsInput::getEnum
    (
        dict, "exchange", exchangeNames, mba::params::exchangeMode::automatic
    );
    // (the solver reads the planned points only)
    params_.stopUnread = true;
    warnUnknownKeywords
    ({
        "tolerance", "relativeTolerance", "maxLevels", "initialGrid",
        "initialApproximation", "thinPlateSplineCoeffs", "bucketTiles", "exchange"
    });
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::multilevelBSplineMotionSolver::multilevelBSplineMotionSolver
(
    const polyMesh& mesh,
    const IOdictionary& dict
)
:
    interpolatingMotionSolver(mesh, dict, typeName)
{
    readCoeffs();
}


Foam::multilevelBSplineMotionSolver::multilevelBSplineMotionSolver
(
    const polyMesh& mesh,
    const IOdictionary& dict,
    const pointVectorField& pointDisplacement,
    const pointIOField& points0
)
:
    interpolatingMotionSolver(mesh, dict, pointDisplacement, points0, typeName)
{
    readCoeffs();
}


// * * * * * * * * * * * * * * * * Destructor  * * * * * * * * * * * * * * * //

Foam::multilevelBSplineMotionSolver::~multilevelBSplineMotionSolver()
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

std::unique_ptr<Foam::boundaryInterpolator>
Foam::multilevelBSplineMotionSolver::newInterpolator
(
    const boundaryConstraints& bc,
    const bool refit
)
{
    const label D = bc.frame().size();
    const std::size_t nEval = evalPoints().size();
    // The values the solver reads at the evaluation points: the first fit's
    // along the axes that constrain() takes out (before the re-fit,
    // matchCyclic and the rigid layers read them) are not; the re-fit's are
    // all read (moveBoundaryPoints matches the cyclic points first)
    std::vector<std::uint8_t> read;
    if (!refit)
    {
        read = bc.interpolatedComponents(evalPoints());
    }
    std::unique_ptr<boundaryInterpolator> interpolator;
    try
    {
        if (D == 3)
        {
            interpolator.reset(new bsplineInterpolator<3>
                (comm_, params_, bc, base(), evalCoordinates(), nEval, std::move(read), trendGrid_, trendLevel_,
                 warnedNotReached_));
        }
        else if (D == 2)
        {
            interpolator.reset(new bsplineInterpolator<2>
                (comm_, params_, bc, base(), evalCoordinates(), nEval, std::move(read), trendGrid_, trendLevel_,
                 warnedNotReached_));
        }
        else
        {
            FatalErrorInFunction
                << "Meshes with " << D << " solution directions are not supported"
                << " (2D or 3D only)" << exit(FatalError);
        }
    }
    catch (const std::exception& e)
    {
        FatalErrorInFunction
            << "Cannot set up the multilevel B-spline plan: " << e.what()
            << exit(FatalError);
    }
    const label nControl = bc.nControlGlobal();
    Info<< type() << ": " << (refit ? "re-fit " : "") << "plan for "
        << nControl << " control points, "
        << nOwnedGlobal(bc.owned()) << " mesh points ("
        << nOwnedGlobal(bc.owned(), evalPoints()) << " interpolated), "
        << bc.frame().name();
    if (Pstream::parRun())
    {
        // The fit's work is per control point: how evenly the ranks hold them
        const label most =
            returnReduce(bc.controlPoints().size(), maxOp<label>());
        const scalar imbalance =
            scalar(most)*Pstream::nProcs()/max(scalar(nControl), scalar(1));
        char ratio[32];
        std::snprintf(ratio, sizeof(ratio), "%.2f", imbalance);
        Info<< "; at most " << most << " on a rank (" << ratio
            << " times the mean)" << endl;
        if (!refit && imbalance >= 1.5)
        {
            Info<< type() << ": the fit's work follows the control points,"
                << " and the busiest rank holds " << ratio << " times the"
                << " mean: a decomposition that gives every rank a share of"
                << " the patches that fix or prescribe the displacement"
                << " balances it (a box's top and bottom: columns,"
                << " hierarchical with n (a b 1))" << endl;
        }
    }
    else
    {
        Info<< endl;
    }
    return interpolator;
}


// ************************************************************************* //
