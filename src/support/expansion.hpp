#pragma once
// Expansion: an exact sum of non-overlapping doubles (J. R. Shewchuk, "Adaptive precision
// floating-point arithmetic and fast robust geometric predicates", DCG 18, 1997, Sec. 2).
// Used by the field-topology verifier (src/topology/field_exact.hpp) and, in builds without GMP
// (CMC33_WITH_GMP=OFF, the WebAssembly build), by the decisions' exact fallback
// (src/core/decide.hpp) and the exact geometric predicates (src/topology/exact_geometry.cpp).
// Exact as long as no product underflows below 2^-969 or overflows; when that happens `lost()`
// is set and the caller must not trust the sign.

#include <cmath>
#include <cstddef>
#include <vector>

namespace cmc33::detail {

/// The rounding error of s = a + b (Knuth's TwoSum): a + b == s + two_sum_tail(a, b, s) exactly.
inline double two_sum_tail(double a, double b, double s) noexcept
{
    const double bv = s - a;
    const double av = s - bv;
    return (a - av) + (b - bv);
}

// ---------------------------------------------------------------------------------------------
// Expansion: the exact value sum(c_), components nonzero, non-overlapping, by increasing
// magnitude; its sign is the sign of the largest component (Shewchuk, Sec. 2.2).
class Expansion {
public:
    Expansion() = default;
    explicit Expansion(double x)
    {
        if (!std::isfinite(x)) lost_ = true;
        if (x != 0.0) c_.push_back(x);
    }
    /// a - b, exactly.
    static Expansion difference(double a, double b)
    {
        Expansion r;
        const double s = a - b;
        const double t = two_sum_tail(a, -b, s);
        if (!std::isfinite(s)) r.lost_ = true;
        if (t != 0.0) r.c_.push_back(t);
        if (s != 0.0) r.c_.push_back(s);
        return r;
    }

    int sign() const noexcept { return c_.empty() ? 0 : (c_.back() > 0.0 ? 1 : -1); }
    /// True when a product underflowed or a value overflowed: the sign may then be wrong.
    bool lost() const noexcept { return lost_; }
    /// Nearest double of the exact value (for messages and tests).
    double estimate() const noexcept
    {
        double s = 0.0;
        for (double c : c_) s += c;
        return s;
    }
    std::size_t size() const noexcept { return c_.size(); }

    friend Expansion operator+(const Expansion& x, const Expansion& y)
    {
        Expansion r = x;
        r.lost_ = x.lost_ || y.lost_;
        for (double b : y.c_) r.grow(b);
        r.compress();
        return r;
    }
    friend Expansion operator-(const Expansion& x, const Expansion& y)
    {
        Expansion r = x;
        r.lost_ = x.lost_ || y.lost_;
        for (double b : y.c_) r.grow(-b);
        r.compress();
        return r;
    }
    friend Expansion operator*(const Expansion& x, const Expansion& y)
    {
        Expansion r;
        r.lost_ = x.lost_ || y.lost_;
        for (double b : y.c_) {
            const Expansion part = x.scaled(b);
            r.lost_ = r.lost_ || part.lost_;
            for (double c : part.c_) r.grow(c);
        }
        r.compress();
        return r;
    }

private:
    // Shewchuk's Grow-Expansion with zero elimination: adds one double, exactly.
    void grow(double b)
    {
        double q = b;
        std::size_t out = 0;
        for (std::size_t i = 0; i < c_.size(); ++i) {
            const double s = q + c_[i];
            const double t = two_sum_tail(q, c_[i], s);
            q = s;
            if (t != 0.0) c_[out++] = t;
        }
        c_.resize(out);
        if (!std::isfinite(q)) lost_ = true;
        if (q != 0.0) c_.push_back(q);
    }

    // Shewchuk's Scale-Expansion with zero elimination (Two-Sum in place of Fast-Two-Sum: the
    // same result wherever Fast-Two-Sum's precondition holds, and exact everywhere).
    Expansion scaled(double b) const
    {
        Expansion r;
        if (c_.empty() || b == 0.0) return r;
        auto product = [&r](double x, double y, double& hi, double& lo) {
            hi = x * y;
            lo = std::fma(x, y, -hi);
            // x, y != 0 (zero-eliminated components, b != 0): a product that underflowed to 0 is lost too
            if (!std::isfinite(hi) || std::fabs(hi) < 0x1p-969) r.lost_ = true;
        };
        double q = 0.0;
        double lo = 0.0;
        product(c_[0], b, q, lo);
        if (lo != 0.0) r.c_.push_back(lo);
        for (std::size_t i = 1; i < c_.size(); ++i) {
            double big = 0.0;
            double small = 0.0;
            product(c_[i], b, big, small);
            const double s1 = q + small;
            const double t1 = two_sum_tail(q, small, s1);
            if (t1 != 0.0) r.c_.push_back(t1);
            const double s2 = big + s1;
            const double t2 = two_sum_tail(big, s1, s2);
            if (t2 != 0.0) r.c_.push_back(t2);
            q = s2;
        }
        if (q != 0.0) r.c_.push_back(q);
        return r;
    }

    // Shewchuk's Compress: the same value in fewer components, still non-overlapping.
    void compress()
    {
        const std::size_t m = c_.size();
        if (m < 2) return;
        std::vector<double> g(m);
        double q = c_[m - 1];
        std::size_t bottom = m - 1;
        for (std::size_t i = m - 1; i-- > 0;) {
            const double s = q + c_[i];
            const double t = two_sum_tail(q, c_[i], s);
            if (t != 0.0) {
                g[bottom--] = s;
                q = t;
            } else {
                q = s;
            }
        }
        g[bottom] = q;
        std::size_t top = 0;
        for (std::size_t i = bottom + 1; i < m; ++i) {
            const double s = g[i] + q;
            const double t = two_sum_tail(g[i], q, s);
            q = s;
            if (t != 0.0) c_[top++] = t;
        }
        if (q != 0.0) c_[top++] = q;
        c_.resize(top);
    }

    std::vector<double> c_;
    bool lost_ = false;
};

} // namespace cmc33::detail
