#pragma once
// A disjoint-set forest over the integers [0, n): union by rank, path halving. Near-constant
// amortized cost per operation (inverse Ackermann). Elements are 32-bit: callers with more than
// 2^32 - 1 elements must check before constructing.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cmc33::detail {

class UnionFind {
public:
    UnionFind() = default;
    explicit UnionFind(std::size_t n) { reset(n); }

    /// n singletons (previous content is discarded).
    void reset(std::size_t n)
    {
        parent_.resize(n);
        rank_.assign(n, 0);
        for (std::size_t i = 0; i < n; ++i) parent_[i] = static_cast<std::uint32_t>(i);
    }

    std::size_t size() const noexcept { return parent_.size(); }

    /// Representative of x's set. Path halving: every other node on the path skips to its
    /// grandparent, which flattens the tree without recursion.
    std::uint32_t find(std::uint32_t x) noexcept
    {
        while (parent_[x] != x) {
            parent_[x] = parent_[parent_[x]];
            x = parent_[x];
        }
        return x;
    }

    /// Merges the sets of a and b. Returns false if they were already one set.
    bool unite(std::uint32_t a, std::uint32_t b) noexcept
    {
        a = find(a);
        b = find(b);
        if (a == b) return false;
        if (rank_[a] < rank_[b]) {
            parent_[a] = b;
        } else {
            parent_[b] = a;
            if (rank_[a] == rank_[b]) ++rank_[a];
        }
        return true;
    }

    /// True iff x is the representative of its set (cheap: no path walk).
    bool is_root(std::uint32_t x) const noexcept { return parent_[x] == x; }

private:
    std::vector<std::uint32_t> parent_;
    std::vector<std::uint8_t> rank_; // rank <= log2(n) < 64: a byte suffices
};

} // namespace cmc33::detail
