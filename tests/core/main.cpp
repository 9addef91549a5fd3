// The core's tests run with the floating-point exceptions trapped that
// OpenFOAM traps in every solver (FOAM_SIGFPE: invalid operation, division
// by zero, overflow), as the core runs inside the motion solvers: such an
// exception anywhere in the core fails the test that raised it (Catch
// reports the SIGFPE). Threads (the simulated ranks) inherit the setting.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <fenv.h>

int main(int argc, char* argv[])
{
    feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
    return Catch::Session().run(argc, argv);
}
