/*---------------------------------------------------------------------------*\
    bsplineMorph: dynamicMeshDict changed while a run goes on
    (runTimeModifiable): the solvers keep the settings they started with and
    say so when their own change.
\*---------------------------------------------------------------------------*/

#include <catch2/catch.hpp>

#include "foamTestCase.H"
#include "motionSolver.H"
#include "IOdictionary.H"
#include "OFstream.H"
#include "OSspecific.H"

#include <iostream>
#include <sstream>

using namespace Foam;

namespace
{
    //- The dictionary file: the solver and its coefficients
    void writeDict(const fileName& file, const std::string& type, const std::string& coeffs)
    {
        OFstream os(file);
        os  << "FoamFile { version 2.0; format ascii; class dictionary; object "
            << file.name() << "; }\n"
            << "motionSolver " << type.c_str() << ";\n"
            << type.c_str() << "Coeffs { " << coeffs.c_str() << " }\n";
    }

    //- What solver.read() writes to the standard output (OpenFOAM's warnings)
    std::string readOutput(motionSolver& solver)
    {
        std::ostringstream captured;
        std::streambuf* old = std::cout.rdbuf(captured.rdbuf());
        const bool ok = solver.read();
        std::cout.rdbuf(old);
        REQUIRE(ok);
        return captured.str();
    }
}


TEST_CASE("A solver's settings changed in dynamicMeshDict during a run: kept, with a warning", "[foam][bsplineMorph][rbf][errors]")
{
    using Catch::Matchers::Contains;
    if (Pstream::parRun())
    {
        // (a file of the case, written and read back by one process)
        SUCCEED("checked by the serial run");
        return;
    }
    const std::string type = GENERATE(as<std::string>(), "multilevelBSpline", "RBF");
    const Time& runTime = bsmTest::mesh().time();
    const fileName file = runTime.path()/runTime.constant()/"morphSettingsTest";
    writeDict(file, type, "rebase off;");
    autoPtr<motionSolver> solver;
    {
        IOdictionary dict
        (
            IOobject
            (
                file.name(),
                runTime.constant(),
                bsmTest::mesh(),
                IOobject::MUST_READ_IF_MODIFIED,
                IOobject::NO_WRITE,
                false
            )
        );
        solver = motionSolver::New(bsmTest::mesh(), dict);
    }
    // Read again unchanged (a comment, say, changed elsewhere): no word
    const std::string same = readOutput(solver.ref());
    CHECK(same.find("changed") == std::string::npos);
    writeDict(file, type, "rebase on;");
    const std::string said = readOutput(solver.ref());
    rm(file);
    CHECK_THAT(said, Contains(type + ": its settings in") && Contains("morphSettingsTest\" changed at time")
        && Contains("read at the start only; the run goes on with those it started with"));
}
