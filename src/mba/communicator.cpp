#include "communicator.hpp"
#include "geometry.hpp"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

namespace mba {

std::vector<double> communicator::sum(const std::vector<double>& mine) const
{
    const std::vector<double> all = allGatherFixed(mine);
    const std::size_t n = mine.size();
    std::vector<double> s(n, 0.0);
    for (std::size_t at = 0; at < all.size(); at += n)
        for (std::size_t i = 0; i < n; ++i) s[i] += all[at + i];
    return s;
}

double communicator::max(double x) const
{
    double m = x;
    for (const double v : allGatherFixed(std::vector<double>{x})) m = std::max(m, v);
    return m;
}

std::int64_t communicator::sum(std::int64_t x) const
{
    std::int64_t s = 0;
    for (const std::int64_t v : allGatherFixed(std::vector<std::int64_t>{x})) s += v;
    return s;
}

void communicator::exchangeInPlace(const std::vector<constByteRange>& send, const std::vector<byteRange>& recv) const
{
    std::vector<bytes> b(size());
    for (int r = 0; r < size(); ++r)
        if (r != rank() && send[r].size) b[r].assign(send[r].data, send[r].data + send[r].size);
    const std::vector<bytes> got = exchangeBytes(b);
    for (int r = 0; r < size(); ++r)
    {
        if (r == rank()) continue;
        if (got[r].size() != recv[r].size)
            throw std::logic_error("mba: rank " + std::to_string(rank()) + " expected " + std::to_string(recv[r].size)
                                   + " bytes from rank " + std::to_string(r) + ", got " + std::to_string(got[r].size()));
        if (recv[r].size) std::memcpy(recv[r].data, got[r].data(), recv[r].size);
    }
}

void communicator::sendReceiveBytes(int to, constByteRange send, int from, byteRange recv) const
{
    std::vector<constByteRange> s(size(), constByteRange{nullptr, 0});
    std::vector<byteRange> r(size(), byteRange{nullptr, 0});
    if (to >= 0) s[to] = send;
    if (from >= 0) r[from] = recv;
    exchangeInPlace(s, r);
}

bytes communicator::allGatherFixedBytes(const bytes& mine) const
{
    const int P = size(), me = rank();
    const std::size_t nb = mine.size();
    // got holds the blocks of ranks me, me + 1, ... (mod P); each round
    // doubles them with the first ones of rank me + have, whose are next
    bytes got(std::size_t(P)*nb);
    if (nb) std::memcpy(got.data(), mine.data(), nb);
    for (int have = 1; have < P; have *= 2)
    {
        const std::size_t n = std::size_t(std::min(have, P - have))*nb;
        sendReceiveBytes((me - have + P)%P, constByteRange{got.data(), n},
                         (me + have)%P, byteRange{got.data() + std::size_t(have)*nb, n});
    }
    // rank r's block is at (r - me) mod P: rank 0's first
    std::rotate(got.begin(), got.begin() + std::ptrdiff_t(std::size_t((P - me)%P)*nb), got.end());
    return got;
}

void communicator::check(bool ok, const std::string& msg) const
{
    // whether any rank failed, in one all-gather of known size; the
    // messages only then
    if (max(ok ? 0.0 : 1.0) == 0) return;
    bytes mine;
    if (!ok) mine.assign(msg.begin(), msg.end()), mine.push_back('\0');
    const auto all = allGather(mine);
    for (std::size_t r = 0; r < all.size(); ++r)
    {
        if (!all[r].empty())
        {
            std::string m(all[r].data());
            if (size() > 1) m += " (rank " + std::to_string(r) + ")";
            throw collectiveError(m);
        }
    }
}

namespace {

struct world
{
    int n;
    std::mutex m;
    std::condition_variable cv;
    int arrived = 0;
    std::uint64_t generation = 0;
    bool broken = false;
    std::vector<bytes> gather;              // [rank]
    std::vector<std::vector<bytes>> mail;   // [from][to]

    explicit world(int n_) : n(n_), gather(n_), mail(n_, std::vector<bytes>(n_)) {}

    void barrier()
    {
        std::unique_lock<std::mutex> lock(m);
        if (broken) throw collectiveError("mba: a simulated rank failed");
        const std::uint64_t gen = generation;
        if (++arrived == n)
        {
            arrived = 0;
            ++generation;
            cv.notify_all();
            return;
        }
        cv.wait(lock, [&] { return generation != gen || broken; });
        if (generation == gen) throw collectiveError("mba: a simulated rank failed");
    }

    void breakAll()
    {
        std::lock_guard<std::mutex> lock(m);
        broken = true;
        cv.notify_all();
    }
};

class simulatedCommunicator : public communicator
{
    world& w_;
    int rank_;

protected:
    std::vector<bytes> allGatherBytes(const bytes& mine) const override
    {
        w_.gather[rank_] = mine;
        w_.barrier();
        std::vector<bytes> all = w_.gather;
        w_.barrier();
        return all;
    }

    std::vector<bytes> exchangeBytes(const std::vector<bytes>& send) const override
    {
        for (int r = 0; r < w_.n; ++r) w_.mail[rank_][r] = send[r];
        w_.barrier();
        std::vector<bytes> got(w_.n);
        for (int r = 0; r < w_.n; ++r) got[r] = w_.mail[r][rank_];
        w_.barrier();
        return got;
    }

public:
    simulatedCommunicator(world& w, int r) : w_(w), rank_(r) {}
    int rank() const override { return rank_; }
    int size() const override { return w_.n; }
};

} // namespace

void runSimulated(int n, const std::function<void(const communicator&)>& body)
{
    precondition(n >= 1, "mba: runSimulated needs at least one rank");
    world w(n);
    std::vector<std::exception_ptr> errors(n);
    std::vector<std::thread> threads;
    for (int r = 0; r < n; ++r)
    {
        threads.emplace_back([&, r] {
            try
            {
                simulatedCommunicator c(w, r);
                body(c);
            }
            catch (...)
            {
                errors[r] = std::current_exception();
                w.breakAll();
            }
        });
    }
    for (auto& t : threads) t.join();
    // Prefer a real error over the "a rank failed" echo of the others
    for (int pass = 0; pass < 2; ++pass)
        for (int r = 0; r < n; ++r)
        {
            if (!errors[r]) continue;
            try { std::rethrow_exception(errors[r]); }
            catch (const collectiveError& e)
            {
                if (pass == 1 || std::string(e.what()) != "mba: a simulated rank failed") throw;
            }
            catch (...) { throw; }
        }
}

const communicator& serial()
{
    static const serialCommunicator comm;
    return comm;
}

} // namespace mba
