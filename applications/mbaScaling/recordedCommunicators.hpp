// mbaScaling's communicators: a simulated rank's, timed and recording what
// each call returned, and a rank's alone, answering from that record
// (--replay; mbaScaling.cpp's header says why). OpenFOAM-free.
#ifndef MBASCALING_RECORDEDCOMMUNICATORS_HPP
#define MBASCALING_RECORDEDCOMMUNICATORS_HPP

#include "communicator.hpp"

#include <time.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace mba {

/// This thread's CPU time [s]
inline double threadSeconds()
{
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9*double(t.tv_nsec);
}

/// What one rank's communication returned, call after call (--replay)
struct callLog
{
    std::vector<std::vector<bytes>> calls;   ///< per call: what came from each rank (one entry: a round's)
    std::size_t next = 0;                    ///< the next call to replay
};

/// A simulated rank's communicator that counts the thread CPU time spent in
/// it: what the simulation costs (copies, barriers of threads that share
/// two cores), which a network replaces; the rank's work is the rest. With
/// a log, it records what every call returned.
class timedCommunicator : public communicator
{
    const communicator& inner_;
    callLog* log_;   ///< records every call's results (null: none)
    mutable double seconds_ = 0;
    mutable long gathers_ = 0, exchanges_ = 0;

    /// (inside timed(): the copies are the simulation's, not the rank's work)
    void record(const std::vector<bytes>& got) const
    {
        if (log_) log_->calls.push_back(got);
    }

    template <class F>
    auto timed(F f) const -> decltype(f())
    {
        const double t = threadSeconds();
        auto r = f();
        seconds_ += threadSeconds() - t;
        return r;
    }

protected:
    std::vector<bytes> allGatherBytes(const bytes& mine) const override
    {
        ++gathers_;
        return timed([&] {
            std::vector<bytes> all = inner_.allGather(mine);
            record(all);
            return all;
        });
    }
    bytes allGatherFixedBytes(const bytes& mine) const override
    {
        ++gathers_;
        return timed([&] {
            bytes all = inner_.allGatherFixed(mine);
            record({all});
            return all;
        });
    }
    std::vector<bytes> exchangeBytes(const std::vector<bytes>& send) const override
    {
        ++exchanges_;
        return timed([&] {
            std::vector<bytes> got = inner_.exchange(send);
            record(got);
            return got;
        });
    }
    void exchangeInPlace(const std::vector<constByteRange>& send, const std::vector<byteRange>& recv) const override
    {
        ++exchanges_;
        // through the simulated ranks' exchange (the in-place one is protected);
        // the copies are the simulation's too (a network reads and writes in place)
        timed([&] {
            std::vector<bytes> b(size());
            for (int r = 0; r < size(); ++r) if (send[r].size) b[r].assign(send[r].data, send[r].data + send[r].size);
            const std::vector<bytes> got = inner_.exchange(b);
            for (int r = 0; r < size(); ++r) if (recv[r].size) std::memcpy(recv[r].data, got[r].data(), recv[r].size);
            record(got);
            return 0;
        });
    }

    void sendReceiveBytes(int to, constByteRange send, int from, byteRange recv) const override
    {
        ++exchanges_;
        // (the simulated ranks have no point-to-point call: theirs goes
        // through an exchange with every rank, whose set-up is theirs too)
        timed([&] {
            inner_.sendReceive(to, send.data, send.size, from, recv.data, recv.size);
            if (log_) record({bytes(recv.data, recv.data + recv.size)});
            return 0;
        });
    }

public:
    explicit timedCommunicator(const communicator& inner, callLog* log = nullptr) : inner_(inner), log_(log) {}
    int rank() const override { return inner_.rank(); }
    int size() const override { return inner_.size(); }
    double seconds() const { return seconds_; }
    long gathers() const { return gathers_; }
    long exchanges() const { return exchanges_; }
};

/// Rank r of P alone, its communication answered from a callLog (--replay)
class replayCommunicator : public communicator
{
    const int rank_, size_;
    callLog& log_;

    const std::vector<bytes>& next() const
    {
        if (log_.next >= log_.calls.size()) throw std::logic_error("mbaScaling: the replay makes more calls than the run");
        return log_.calls[log_.next++];
    }
    static void copy(const bytes& from, byteRange to)
    {
        if (from.size() != to.size) throw std::logic_error("mbaScaling: the replay expects other sizes than the run");
        if (to.size) std::memcpy(to.data, from.data(), to.size);
    }

protected:
    std::vector<bytes> allGatherBytes(const bytes& mine) const override
    {
        const std::vector<bytes>& all = next();
        if (all.at(rank_) != mine) throw std::logic_error("mbaScaling: the replay departs from the run");
        return all;
    }
    bytes allGatherFixedBytes(const bytes& mine) const override
    {
        const bytes& all = next().at(0);
        if (all.size() != std::size_t(size_)*mine.size()
            || !std::equal(mine.begin(), mine.end(), all.begin() + std::ptrdiff_t(std::size_t(rank_)*mine.size())))
            throw std::logic_error("mbaScaling: the replay departs from the run");
        return all;
    }
    std::vector<bytes> exchangeBytes(const std::vector<bytes>&) const override { return next(); }
    void exchangeInPlace(const std::vector<constByteRange>&, const std::vector<byteRange>& recv) const override
    {
        const std::vector<bytes>& got = next();
        for (int r = 0; r < size_; ++r) if (r != rank_) copy(got.at(r), recv[r]);
    }
    void sendReceiveBytes(int, constByteRange, int, byteRange recv) const override { copy(next().at(0), recv); }

public:
    replayCommunicator(int r, int P, callLog& log) : rank_(r), size_(P), log_(log) {}
    int rank() const override { return rank_; }
    int size() const override { return size_; }
};

} // namespace mba
#endif
