// bsplineMorph: OpenFOAM-free multilevel B-spline core
// The small communication interface the distributed algorithm is written against.
//
// Implementations provide rank/size and two byte-level collectives; typed
// helpers, the all-gather of one size (over point-to-point rounds),
// reductions (summed in rank order, so every rank gets bitwise the same
// result) and the collective check are built on them here, once.
#ifndef MBA_COMMUNICATOR_HPP
#define MBA_COMMUNICATOR_HPP

#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace mba {

using bytes = std::vector<char>;

/// Thrown on every rank when a collective check fails on any rank
struct collectiveError : std::runtime_error
{
    using std::runtime_error::runtime_error;
};

/// Traffic counters (point-to-point payload; collectives counted separately)
struct trafficStats
{
    std::uint64_t messagesSent = 0, bytesSent = 0;
    std::uint64_t messagesReceived = 0, bytesReceived = 0;
    std::uint64_t collectiveBytes = 0;   ///< bytes this rank contributed to all-gathers
};

/// Bytes to send, or to receive into
struct constByteRange
{
    const char* data;
    std::size_t size;
};

struct byteRange
{
    char* data;
    std::size_t size;
};

class communicator
{
    mutable trafficStats traffic_;

protected:
    /// Every rank receives every rank's buffer (index = rank)
    virtual std::vector<bytes> allGatherBytes(const bytes& mine) const = 0;
    /// send[r] goes to rank r (empty: no message); returns what rank r sent here
    virtual std::vector<bytes> exchangeBytes(const std::vector<bytes>& send) const = 0;
    /// send[r] goes to rank r; what rank r sends comes into recv[r], whose
    /// size this rank knows (as in every apply of a plan: no sizes need to
    /// travel, nothing is allocated); size 0: no message; this rank's own
    /// entries are ignored. By default through exchangeBytes, sizes checked.
    virtual void exchangeInPlace(const std::vector<constByteRange>& send, const std::vector<byteRange>& recv) const;
    /// send goes to rank to and rank from's message comes into recv, whose
    /// size this rank knows (a round of treeSum): one partner each way
    /// (-1 or size 0: none). Collective in that every rank calls it the same
    /// number of times; an implementation may let a rank without partners
    /// return at once. By default through exchangeInPlace.
    virtual void sendReceiveBytes(int to, constByteRange send, int from, byteRange recv) const;
    /// Every rank's mine, whose size is the same on every rank (the
    /// caller's promise: a rank that passes another size is an error of
    /// the transport), concatenated in rank order. By default the Bruck
    /// all-gather over sendReceiveBytes: ceil(log2 P) rounds of one
    /// message each way (a gather and a scatter over a tree take twice
    /// as many), carrying nothing but the values.
    virtual bytes allGatherFixedBytes(const bytes& mine) const;

private:
    /// This rank's values as the bytes it contributes to an all-gather
    /// (counted as collective traffic)
    template <class T>
    bytes collectiveBytesOf(const std::vector<T>& mine) const
    {
        static_assert(std::is_trivially_copyable<T>::value, "plain data only");
        bytes b(mine.size()*sizeof(T));
        if (!b.empty()) std::memcpy(b.data(), mine.data(), b.size());
        traffic_.collectiveBytes += b.size();
        return b;
    }

public:
    virtual ~communicator() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;

    const trafficStats& traffic() const { return traffic_; }

    template <class T>
    std::vector<std::vector<T>> allGather(const std::vector<T>& mine) const
    {
        const std::vector<bytes> all = allGatherBytes(collectiveBytesOf(mine));
        std::vector<std::vector<T>> out(all.size());
        for (std::size_t r = 0; r < all.size(); ++r) out[r] = fromBytes<T>(all[r]);
        return out;
    }

    /// allGather of the same number of values from every rank, as one
    /// array: rank r's n = mine.size() values at [r n, (r + 1) n). One
    /// array, not one a rank: for the few values a rank adds to a sum or
    /// a maximum. Every rank must pass the same n (allGatherFixedBytes)
    template <class T>
    std::vector<T> allGatherFixed(const std::vector<T>& mine) const
    {
        return fromBytes<T>(allGatherFixedBytes(collectiveBytesOf(mine)));
    }

    template <class T>
    std::vector<std::vector<T>> exchange(const std::vector<std::vector<T>>& send) const
    {
        static_assert(std::is_trivially_copyable<T>::value, "plain data only");
        std::vector<bytes> b(size());
        for (int r = 0; r < size(); ++r)
        {
            if (r >= int(send.size()) || send[r].empty()) continue;
            b[r].resize(send[r].size()*sizeof(T));
            std::memcpy(b[r].data(), send[r].data(), b[r].size());
            if (r != rank()) { ++traffic_.messagesSent; traffic_.bytesSent += b[r].size(); }
        }
        const std::vector<bytes> got = exchangeBytes(b);
        std::vector<std::vector<T>> out(got.size());
        for (std::size_t r = 0; r < got.size(); ++r)
        {
            if (!got[r].empty() && int(r) != rank())
            {
                ++traffic_.messagesReceived;
                traffic_.bytesReceived += got[r].size();
            }
            out[r] = fromBytes<T>(got[r]);
        }
        return out;
    }

    /// exchange into arrays this rank has sized to what each rank sends it
    /// (recv[r].size() values; the plan of an apply knows them): no sizes
    /// travel, nothing is allocated. This rank's own entries are ignored.
    template <class T>
    void exchange(const std::vector<std::vector<T>>& send, std::vector<std::vector<T>>& recv) const
    {
        static_assert(std::is_trivially_copyable<T>::value, "plain data only");
        std::vector<constByteRange> s(size(), constByteRange{nullptr, 0});
        std::vector<byteRange> r(size(), byteRange{nullptr, 0});
        for (int q = 0; q < size(); ++q)
        {
            if (q == rank()) continue;
            if (q < int(send.size()) && !send[q].empty())
            {
                s[q] = constByteRange{reinterpret_cast<const char*>(send[q].data()), send[q].size()*sizeof(T)};
                ++traffic_.messagesSent;
                traffic_.bytesSent += s[q].size;
            }
            if (q < int(recv.size()) && !recv[q].empty())
            {
                r[q] = byteRange{reinterpret_cast<char*>(recv[q].data()), recv[q].size()*sizeof(T)};
                ++traffic_.messagesReceived;
                traffic_.bytesReceived += r[q].size;
            }
        }
        exchangeInPlace(s, r);
    }

    /// n values to rank to and m from rank from (sendReceiveBytes; -1 or 0: none)
    template <class T>
    void sendReceive(int to, const T* send, std::size_t n, int from, T* recv, std::size_t m) const
    {
        static_assert(std::is_trivially_copyable<T>::value, "plain data only");
        constByteRange s{nullptr, 0};
        byteRange r{nullptr, 0};
        if (to >= 0 && to != rank() && n > 0)
        {
            s = constByteRange{reinterpret_cast<const char*>(send), n*sizeof(T)};
            ++traffic_.messagesSent;
            traffic_.bytesSent += s.size;
        }
        if (from >= 0 && from != rank() && m > 0)
        {
            r = byteRange{reinterpret_cast<char*>(recv), m*sizeof(T)};
            ++traffic_.messagesReceived;
            traffic_.bytesReceived += r.size;
        }
        sendReceiveBytes(s.size ? to : -1, s, r.size ? from : -1, r);
    }

    /// Element-wise sum over ranks, added in rank order: identical on every rank
    std::vector<double> sum(const std::vector<double>& mine) const;
    double sum(double x) const { return sum(std::vector<double>{x})[0]; }
    double max(double x) const;
    double min(double x) const { return -max(-x); }
    std::int64_t sum(std::int64_t x) const;

    /// Collective check: when ok is false on any rank, every rank throws
    /// collectiveError with the message of the lowest failing rank
    void check(bool ok, const std::string& msg) const;

private:
    template <class T>
    static std::vector<T> fromBytes(const bytes& b)
    {
        std::vector<T> v(b.size()/sizeof(T));
        if (!v.empty()) std::memcpy(v.data(), b.data(), v.size()*sizeof(T));
        return v;
    }
};

/// One process, one rank
class serialCommunicator : public communicator
{
protected:
    std::vector<bytes> allGatherBytes(const bytes& mine) const override { return {mine}; }
    std::vector<bytes> exchangeBytes(const std::vector<bytes>& send) const override { return send; }

public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
};

/// The serial communicator (one for the process, never destroyed before its
/// users: pass this rather than a temporary serialCommunicator)
const communicator& serial();

/// Run body on n simulated ranks (threads of this process), each with its own
/// communicator. Exceptions are rethrown after all ranks finished (the lowest
/// rank's first); a rank that dies makes the others' next collective throw
/// instead of waiting forever.
void runSimulated(int n, const std::function<void(const communicator&)>& body);

} // namespace mba
#endif
