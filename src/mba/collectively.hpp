// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// A step that fails on every rank together: one rank never throws alone
// (the others would wait for it in their next collective).
#ifndef MBA_COLLECTIVELY_HPP
#define MBA_COLLECTIVELY_HPP

#include "communicator.hpp"

#include <stdexcept>
#include <string>

namespace mba {

/// Runs f; an std::invalid_argument on any rank becomes the same error on all
template <class F>
void collectively(const communicator& comm, F&& f)
{
    std::string err;
    try { f(); }
    catch (const std::invalid_argument& e) { err = e.what(); }
    comm.check(err.empty(), err);
}

} // namespace mba
#endif
