/*---------------------------------------------------------------------------*\
Application
    foamTests

Description
    Catch2 (v2) runner for the OpenFOAM-side tests of bsplineMorph.

    foamTests [OpenFOAM options: -case DIR -parallel ...] [-- Catch2 options]

    One argList, Time and fvMesh for the whole process: argList's destructor
    calls Pstream::exit(0), so it is created once and never destroyed. Fatal
    errors throw (FatalError.throwExceptions()) so tests can REQUIRE_THROWS
    them. The number of failed tests is summed over all ranks and returned
    through UPstream::exit: a failure on any one rank fails every rank.
\*---------------------------------------------------------------------------*/

#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "foamTestCase.H"
#include "IOstreams.H"
#include "Pstream.H"
#include "IOdictionary.H"
#include "IStringStream.H"

namespace
{
    Foam::argList* argsPtr = nullptr;
    Foam::Time* runTimePtr = nullptr;
    Foam::fvMesh* meshPtr = nullptr;
}

Foam::argList& bsmTest::args() { return *argsPtr; }
Foam::Time& bsmTest::runTime() { return *runTimePtr; }
Foam::fvMesh& bsmTest::mesh() { return *meshPtr; }

Foam::autoPtr<Foam::motionSolver> bsmTest::solverOf
(
    const std::string& type,
    const std::string& coeffs
)
{
    using namespace Foam;
    IOdictionary dict
    (
        IOobject
        (
            "dynamicMeshDict",
            mesh().time().constant(),
            mesh(),
            IOobject::NO_READ,
            IOobject::NO_WRITE,
            false
        ),
        dictionary
        (
            IStringStream
            (
                "motionSolver " + type + "; " + type + "Coeffs {" + coeffs + "}"
            )()
        )
    );
    return motionSolver::New(mesh(), dict);
}


int main(int argc, char* argv[])
{
    // OpenFOAM's arguments before "--", Catch2's after
    int nFoam = argc;
    for (int i = 1; i < argc; ++i)
    {
        if (std::string(argv[i]) == "--") { nFoam = i; break; }
    }
    std::vector<char*> catchArgv{argv[0]};
    for (int i = nFoam + 1; i < argc; ++i) catchArgv.push_back(argv[i]);

    Foam::argList::noFunctionObjects();
    argsPtr = new Foam::argList(nFoam, argv);       // never destroyed
    Foam::FatalError.throwExceptions();
    Foam::FatalIOError.throwExceptions();

    runTimePtr = new Foam::Time(Foam::Time::controlDictName, *argsPtr);
    meshPtr = new Foam::fvMesh
    (
        Foam::IOobject
        (
            Foam::fvMesh::defaultRegion,
            runTimePtr->timeName(),
            *runTimePtr,
            Foam::IOobject::MUST_READ
        )
    );

    Catch::Session session;
    int failed = session.applyCommandLine(int(catchArgv.size()), catchArgv.data());
    if (failed == 0)
    {
        failed = session.run();
    }
    const Foam::label total = Foam::returnReduce(Foam::label(failed), Foam::sumOp<Foam::label>());
    if (Foam::Pstream::parRun())
    {
        Foam::Pout<< "foamTests: " << failed << " failed test case(s) on this rank, "
            << total << " on all ranks" << Foam::endl;
    }
    delete meshPtr;
    delete runTimePtr;
    Foam::UPstream::exit(total > 0 ? 1 : 0);
    return 1;   // not reached
}
