#pragma once
// Smoothed labels (docs/labels.md, "Smooth labels"): each label's indicator filtered by a Gaussian
// of sigma voxels, the label map those filtered indicators give (each sample to the label whose
// filtered indicator is largest, ties to the lower label), and each label's filtered indicator at
// the samples, for the crossings and face decisions of the partition of that map.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/volume.hpp"
#include "parallel.hpp"

namespace cmc33::label_smooth {

/// The Gaussian's taps w[0..r] (w[d] = exp(-d^2 / (2 sigma^2)), r = ceil(3 sigma), at most the
/// grid's longest axis): beyond three sigma a tap is below 1.2 % of the centre's.
inline std::vector<double> gaussian_taps(double sigma, std::int64_t longest)
{
    const double reach = std::ceil(3 * sigma);
    const auto r = static_cast<std::int64_t>(std::min(reach, static_cast<double>(std::max<std::int64_t>(longest, 1))));
    std::vector<double> w(static_cast<std::size_t>(r + 1));
    for (std::int64_t d = 0; d <= r; ++d)
        w[static_cast<std::size_t>(d)] = std::exp(-0.5 * static_cast<double>(d * d) / (sigma * sigma));
    return w;
}

/// One label's filtered indicator on its box: the samples within r of the label's own, where
/// every other sample's value is exactly 0.
struct Box {
    std::int64_t label = 0;
    std::array<std::int64_t, 3> lo{}, hi{}; ///< inclusive sample ranges
    std::vector<float> f;                   ///< x fastest
    std::int64_t nx() const { return hi[0] - lo[0] + 1; }
    std::int64_t ny() const { return hi[1] - lo[1] + 1; }
    bool contains(std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        return lo[0] <= i && i <= hi[0] && lo[1] <= j && j <= hi[1] && lo[2] <= k && k <= hi[2];
    }
    float at(std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        if (!contains(i, j, k)) return 0.0F;
        return f[static_cast<std::size_t>((i - lo[0]) + nx() * ((j - lo[1]) + ny() * (k - lo[2])))];
    }
};

/// The smoothed label map of a grid and its labels' filtered indicators.
template <class T> class Smoothed {
public:
    /// @throws Error{invalid_argument} unless sigma is finite and positive.
    Smoothed(const GridView<T>& g, double sigma, int threads)
    {
        if (!(sigma > 0) || !std::isfinite(sigma)) {
            throw Error(Status::invalid_argument,
                        "smooth: sigma must be 0 (off) or a finite number of voxels above 0, got " +
                            std::to_string(sigma));
        }
        const std::array<std::int64_t, 3> n{g.nx(), g.ny(), g.nz()};
        const std::vector<double> w = gaussian_taps(sigma, std::max({n[0], n[1], n[2]}));
        const auto r = static_cast<std::int64_t>(w.size()) - 1;
        find_boxes(g, r);
        for (Box& b : boxes_) filter(g, b, w, threads);
        labels_.resize(static_cast<std::size_t>(n[0] * n[1] * n[2]));
        view_ = GridView<T>::dense(labels_.data(), {n[0], n[1], n[2]}, g.spacing, g.origin, g.direction);
        choose(threads);
    }

    /// The smoothed label map, dense, in the input's frame.
    const GridView<T>& view() const { return view_; }

    /// The filtered indicator of `label` at a sample (0 for a label not in the input).
    float value(std::int64_t label, std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        const auto it = std::lower_bound(boxes_.begin(), boxes_.end(), label,
                                         [](const Box& b, std::int64_t l) { return b.label < l; });
        return it != boxes_.end() && it->label == label ? it->at(i, j, k) : 0.0F;
    }

    /// f_low - f_high at a sample, rounded to a float: >= 0 exactly where the sample is nearer low
    /// than high (ties to the lower label), and a float, so that the products of two such values
    /// are exact in double and a face's saddle sign is decided exactly.
    double difference(std::int64_t low, std::int64_t high, std::int64_t i, std::int64_t j, std::int64_t k) const
    {
        const double d = static_cast<double>(value(low, i, j, k)) - static_cast<double>(value(high, i, j, k));
        return static_cast<double>(static_cast<float>(d));
    }

private:
    // Each label's bounding box grown by r and cut to the grid.
    void find_boxes(const GridView<T>& g, std::int64_t r)
    {
        std::size_t last = 0; // the box of the sample before, found again only when the label changes
        for (std::int64_t k = 0; k < g.nz(); ++k)
            for (std::int64_t j = 0; j < g.ny(); ++j)
                for (std::int64_t i = 0; i < g.nx(); ++i) {
                    const auto l = static_cast<std::int64_t>(g(i, j, k));
                    if (boxes_.empty() || boxes_[last].label != l) {
                        const auto it = std::lower_bound(boxes_.begin(), boxes_.end(), l,
                                                         [](const Box& b, std::int64_t v) { return b.label < v; });
                        if (it == boxes_.end() || it->label != l) {
                            Box b;
                            b.label = l;
                            b.lo = {i, j, k};
                            b.hi = {i, j, k};
                            last = static_cast<std::size_t>(it - boxes_.begin());
                            boxes_.insert(it, b);
                        } else {
                            last = static_cast<std::size_t>(it - boxes_.begin());
                        }
                    }
                    Box& b = boxes_[last];
                    const std::array<std::int64_t, 3> p{i, j, k};
                    for (std::size_t a = 0; a < 3; ++a) {
                        b.lo[a] = std::min(b.lo[a], p[a]);
                        b.hi[a] = std::max(b.hi[a], p[a]);
                    }
                }
        const std::array<std::int64_t, 3> n{g.nx(), g.ny(), g.nz()};
        for (Box& b : boxes_) {
            for (std::size_t a = 0; a < 3; ++a) {
                b.lo[a] = std::max<std::int64_t>(0, b.lo[a] - r);
                b.hi[a] = std::min<std::int64_t>(n[a] - 1, b.hi[a] + r);
            }
        }
    }

    // The box's indicator filtered along x, y and z in turn. The label's samples lie r inside the
    // box (or at the grid's edge), so each pass reads nothing the box leaves out. At the grid's
    // edges the taps are renormalised to the samples there: the filtered indicators of all labels
    // still sum to 1 at every sample.
    static void filter(const GridView<T>& g, Box& b, const std::vector<double>& w, int threads)
    {
        const std::array<std::int64_t, 3> n{g.nx(), g.ny(), g.nz()};
        const std::array<std::int64_t, 3> size{b.nx(), b.ny(), b.hi[2] - b.lo[2] + 1};
        b.f.assign(static_cast<std::size_t>(size[0] * size[1] * size[2]), 0.0F);
        for (std::int64_t k = 0; k < size[2]; ++k)
            for (std::int64_t j = 0; j < size[1]; ++j)
                for (std::int64_t i = 0; i < size[0]; ++i) {
                    if (static_cast<std::int64_t>(g(b.lo[0] + i, b.lo[1] + j, b.lo[2] + k)) == b.label)
                        b.f[static_cast<std::size_t>(i + size[0] * (j + size[1] * k))] = 1.0F;
                }
        const auto r = static_cast<std::int64_t>(w.size()) - 1;
        const std::array<std::int64_t, 3> stride{1, size[0], size[0] * size[1]};
        for (std::size_t a = 0; a < 3; ++a) {
            // the lines along axis a: one per sample of the other two axes
            const std::size_t u = (a + 1) % 3, v = (a + 2) % 3;
            const std::int64_t lines = size[u] * size[v];
            // 1 / (the taps inside the grid) at each position of the box along a
            std::vector<double> norm(static_cast<std::size_t>(size[a]));
            for (std::int64_t x = 0; x < size[a]; ++x) {
                const std::int64_t at = b.lo[a] + x;
                double s = 0;
                for (std::int64_t d = -r; d <= r; ++d)
                    if (at + d >= 0 && at + d < n[a]) s += w[static_cast<std::size_t>(std::abs(d))];
                norm[static_cast<std::size_t>(x)] = 1 / s;
            }
            detail::parallel_chunks(
                lines, detail::threads_for(threads, lines / 4096 + 1), [&](int, std::int64_t l0, std::int64_t l1) {
                    std::vector<double> in(static_cast<std::size_t>(size[a]));
                    for (std::int64_t l = l0; l < l1; ++l) {
                        const std::int64_t base = (l % size[u]) * stride[u] + (l / size[u]) * stride[v];
                        for (std::int64_t x = 0; x < size[a]; ++x)
                            in[static_cast<std::size_t>(x)] =
                                static_cast<double>(b.f[static_cast<std::size_t>(base + x * stride[a])]);
                        for (std::int64_t x = 0; x < size[a]; ++x) {
                            double s = 0;
                            const std::int64_t from = std::max<std::int64_t>(0, x - r),
                                               to = std::min<std::int64_t>(size[a] - 1, x + r);
                            for (std::int64_t y = from; y <= to; ++y)
                                s += w[static_cast<std::size_t>(std::abs(y - x))] * in[static_cast<std::size_t>(y)];
                            b.f[static_cast<std::size_t>(base + x * stride[a])] =
                                static_cast<float>(s * norm[static_cast<std::size_t>(x)]);
                        }
                    }
                });
        }
    }

    // Each sample's label: the largest filtered indicator, the lower label on a tie (labels in
    // ascending order, replaced only by a larger value). Every sample is in its own label's box
    // with a value above 0, so every sample gets a label.
    void choose(int threads)
    {
        std::vector<float> best(labels_.size(), -1.0F);
        const std::int64_t nx = view_.nx(), ny = view_.ny(), nz = view_.nz();
        detail::parallel_chunks(nz, detail::threads_for(threads, nz), [&](int, std::int64_t z0, std::int64_t z1) {
            for (const Box& b : boxes_) {
                for (std::int64_t k = std::max(z0, b.lo[2]); k < std::min(z1, b.hi[2] + 1); ++k)
                    for (std::int64_t j = b.lo[1]; j <= b.hi[1]; ++j)
                        for (std::int64_t i = b.lo[0]; i <= b.hi[0]; ++i) {
                            const float f = b.at(i, j, k);
                            const auto s = static_cast<std::size_t>(i + nx * (j + ny * k));
                            if (f > best[s]) {
                                best[s] = f;
                                labels_[s] = static_cast<T>(b.label);
                            }
                        }
            }
        });
    }

    std::vector<Box> boxes_; ///< ascending by label
    std::vector<T> labels_;
    GridView<T> view_;
};

} // namespace cmc33::label_smooth
