// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Open-addressing hash map from 64-bit keys to 32-bit values (tile key -> tile id).
#ifndef MBA_HASHMAP_HPP
#define MBA_HASHMAP_HPP

#include <cstdint>
#include <vector>

namespace mba {

class hashMap
{
    static constexpr std::uint64_t emptyKey = ~std::uint64_t(0);
    std::vector<std::uint64_t> keys_;
    std::vector<std::int32_t> vals_;
    std::uint64_t mask_ = 0;
    int shift_ = 64;
    std::size_t size_ = 0;

    std::uint64_t slot(std::uint64_t k) const
    {
        return (k*0x9E3779B97F4A7C15ull) >> shift_;
    }

    void rehash(std::size_t cap)
    {
        std::vector<std::uint64_t> k(cap, emptyKey);
        std::vector<std::int32_t> v(cap, -1);
        keys_.swap(k);
        vals_.swap(v);
        mask_ = cap - 1;
        shift_ = 64;
        for (std::size_t c = cap; c > 1; c >>= 1) --shift_;
        size_ = 0;
        for (std::size_t i = 0; i < k.size(); ++i)
            if (k[i] != emptyKey) insert(k[i], v[i]);
    }

public:
    hashMap() { rehash(16); }

    std::size_t size() const { return size_; }
    std::size_t bytes() const { return keys_.size()*(sizeof(std::uint64_t) + sizeof(std::int32_t)); }

    /// The value of key, or -1
    std::int32_t find(std::uint64_t key) const
    {
        for (std::uint64_t i = slot(key);; i = (i + 1) & mask_)
        {
            if (keys_[i] == key) return vals_[i];
            if (keys_[i] == emptyKey) return -1;
        }
    }

    /// Inserts key -> val unless key is present; returns the stored value
    std::int32_t insert(std::uint64_t key, std::int32_t val)
    {
        if (2*(size_ + 1) > keys_.size()) rehash(2*keys_.size());
        for (std::uint64_t i = slot(key);; i = (i + 1) & mask_)
        {
            if (keys_[i] == key) return vals_[i];
            if (keys_[i] == emptyKey)
            {
                keys_[i] = key;
                vals_[i] = val;
                ++size_;
                return val;
            }
        }
    }
};

} // namespace mba
#endif
