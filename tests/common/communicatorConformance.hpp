// bsplineMorph: one conformance suite for every mba::communicator
// implementation (serial, simulated ranks, Pstream under mpirun).
//
// communicatorConformance(comm) runs on every rank of comm and uses Catch2
// assertions (serialised, so simulated ranks in threads can share them); it
// must be called collectively (all ranks, same order).
#ifndef BSM_COMMUNICATOR_CONFORMANCE_HPP
#define BSM_COMMUNICATOR_CONFORMANCE_HPP

#include "communicator.hpp"

#include <catch2/catch.hpp>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace bsmTest {

/// Catch2 assertions are not thread safe: simulated ranks take turns
inline std::mutex& assertionMutex()
{
    static std::mutex m;
    return m;
}

#define BSM_CHECK(expr) do { std::lock_guard<std::mutex> bsmLock_(bsmTest::assertionMutex()); CHECK(expr); } while (0)
#define BSM_REQUIRE(expr) do { std::lock_guard<std::mutex> bsmLock_(bsmTest::assertionMutex()); REQUIRE(expr); } while (0)

inline void communicatorConformance(const mba::communicator& comm)
{
    const int P = comm.size(), me = comm.rank();
    BSM_REQUIRE(P >= 1);
    BSM_REQUIRE(me >= 0);
    BSM_REQUIRE(me < P);

    // all-gather: rank r contributes r+1 values r*10+i; empty contributions allowed
    {
        std::vector<std::int64_t> mine;
        for (int i = 0; i <= me; ++i) mine.push_back(me*10 + i);
        const auto all = comm.allGather(mine);
        BSM_REQUIRE(int(all.size()) == P);
        for (int r = 0; r < P; ++r)
        {
            BSM_REQUIRE(int(all[r].size()) == r + 1);
            for (int i = 0; i <= r; ++i) BSM_CHECK(all[r][i] == r*10 + i);
        }
        const auto none = comm.allGather(std::vector<double>{});
        BSM_REQUIRE(int(none.size()) == P);
        for (const auto& v : none) BSM_CHECK(v.empty());
    }

    // all-gather of one size on every rank (allGatherFixed), of 0, 1 and 3
    // values a rank: rank r's at [r n, (r + 1) n), the bits it sent
    for (const int n : {0, 1, 3})
    {
        std::vector<double> mine(n);
        for (int i = 0; i < n; ++i) mine[i] = me + 1.0/3 + 1e-3*i;
        const std::vector<double> all = comm.allGatherFixed(mine);
        BSM_REQUIRE(all.size() == std::size_t(P*n));
        for (int r = 0; r < P; ++r)
            for (int i = 0; i < n; ++i) BSM_CHECK(all[r*n + i] == r + 1.0/3 + 1e-3*i);
    }

    // reductions: exact values, identical on every rank (collectives are
    // called outside the assertions: those take turns)
    {
        const double s = comm.sum(double(me) + 0.5);
        const double mx = comm.max(double(me));
        const double mn = comm.min(double(me) - 3);
        const std::int64_t si = comm.sum(std::int64_t(me + 1));
        BSM_CHECK(s == double(P)*(P - 1)/2 + 0.5*P);
        BSM_CHECK(mx == double(P - 1));
        BSM_CHECK(mn == -3.0);
        BSM_CHECK(si == std::int64_t(P)*(P + 1)/2);
        // a sum that depends on the order of addition: the same bits everywhere
        const double tricky = comm.sum(me % 2 ? 1e16 : 1.0);
        const auto seen = comm.allGather(std::vector<double>{tricky});
        for (const auto& v : seen) BSM_CHECK(v[0] == tricky);
        const std::vector<double> vs = comm.sum(std::vector<double>{1.0, double(me)});
        BSM_REQUIRE(vs.size() == 2);
        BSM_CHECK(vs[0] == double(P));
        BSM_CHECK(vs[1] == double(P)*(P - 1)/2);
    }

    // point-to-point exchange: rank me sends (me+1)*(to+1) values to 'to' when
    // (me + to) is even, nothing otherwise (so some pairs exchange no message)
    {
        std::vector<std::vector<double>> send(P);
        for (int to = 0; to < P; ++to)
            if ((me + to) % 2 == 0)
                for (int i = 0; i < (me + 1)*(to + 1); ++i) send[to].push_back(1000.0*me + to + 1e-3*i);
        const auto got = comm.exchange(send);
        BSM_REQUIRE(int(got.size()) == P);
        for (int from = 0; from < P; ++from)
        {
            if ((me + from) % 2 != 0) { BSM_CHECK(got[from].empty()); continue; }
            BSM_REQUIRE(int(got[from].size()) == (from + 1)*(me + 1));
            for (int i = 0; i < int(got[from].size()); ++i)
                BSM_CHECK(got[from][i] == 1000.0*from + me + 1e-3*i);
        }
    }

    // the same into arrays sized by the receiver (no sizes travel), twice
    // with the same arrays (as every apply of a plan does), the second time
    // with other values
    {
        std::vector<std::vector<double>> send(P), recv(P);
        for (int pass = 0; pass < 2; ++pass)
        {
            for (int q = 0; q < P; ++q)
            {
                send[q].clear();
                if (q != me && (me + q) % 2 == 0)
                    for (int i = 0; i < (me + 1)*(q + 1); ++i) send[q].push_back(1000.0*me + q + 1e-3*i + pass);
                recv[q].assign(q != me && (me + q) % 2 == 0 ? std::size_t((q + 1)*(me + 1)) : 0, -1.0);
            }
            comm.exchange(send, recv);
            for (int from = 0; from < P; ++from)
            {
                if (from == me || (me + from) % 2 != 0) { BSM_CHECK(recv[from].empty()); continue; }
                BSM_REQUIRE(int(recv[from].size()) == (from + 1)*(me + 1));
                for (int i = 0; i < int(recv[from].size()); ++i)
                    BSM_CHECK(recv[from][i] == 1000.0*from + me + 1e-3*i + pass);
            }
        }
    }

    // one partner each way (a round of treeSum): along a ring, rank me sends
    // me + 1 values to the next and receives from the previous; then the
    // last rank sits a round out (its neighbours skip it), twice over
    if (P > 1)
    {
        const int next = (me + 1) % P, prev = (me + P - 1) % P;
        std::vector<double> send(me + 1), recv(prev + 1, -1.0);
        for (int i = 0; i <= me; ++i) send[i] = 100.0*me + i;
        comm.sendReceive(next, send.data(), send.size(), prev, recv.data(), recv.size());
        for (int i = 0; i <= prev; ++i) BSM_CHECK(recv[i] == 100.0*prev + i);
        for (int pass = 0; pass < 2; ++pass)
        {
            const bool out = me == P - 1, toOut = next == P - 1, fromOut = prev == P - 1;
            const int to = out || toOut ? -1 : next, from = out || fromOut ? -1 : prev;
            std::vector<double> got(from >= 0 ? std::size_t(prev + 1) : 0, -1.0);
            for (int i = 0; i <= me; ++i) send[i] = 100.0*me + i + pass;
            comm.sendReceive(to, send.data(), to >= 0 ? send.size() : 0, from, got.data(), got.size());
            for (std::size_t i = 0; i < got.size(); ++i) BSM_CHECK(got[i] == 100.0*prev + double(i) + pass);
        }
    }

    // collective check: passes everywhere, or throws the same message on every rank
    {
        comm.check(true, "unused");   // must not throw
        std::string msg;
        try
        {
            comm.check(me != P - 1, "bad input on the last rank");
        }
        catch (const mba::collectiveError& e)
        {
            msg = e.what();
        }
        BSM_CHECK(msg.find("bad input on the last rank") != std::string::npos);
    }
}

} // namespace bsmTest
#endif
