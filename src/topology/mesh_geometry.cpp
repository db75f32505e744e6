// The mesh in space: coincident vertices, zero-area triangles, improperly meeting triangle pairs,
// and the topology after welding by position (contract in src/topology/include/cmc33/topology.hpp).
//
//   1. weld: vertices sorted by position; equal floats (with -0 == +0) share one welded id;
//   2. triangles whose welded corners repeat or are collinear (exactly) are zero-area;
//   3. the others go into the buckets of a uniform grid whose spacing is twice the 90th percentile
//      of the triangle extents (a bucket key per grid cell a triangle's box overlaps), sorted by
//      key; triangles that would span more than 512 cells go to a coarser grid, level by level;
//   4. in each bucket, every pair whose closed boxes overlap is tested once (in the bucket that
//      holds the low corner of the boxes' intersection) with the exact tests of exact_geometry.hpp,
//      according to how many welded corners the two triangles share.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/topology.hpp"
#include "exact_geometry.hpp"
#include "parallel.hpp"

namespace cmc33 {
namespace {

using detail::Point3;

struct Box {
    Point3 lo, hi;
};

bool boxes_overlap(const Box& a, const Box& b)
{
    for (std::size_t k = 0; k < 3; ++k)
        if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
    return true;
}

struct Entry {
    std::uint64_t key;
    std::uint32_t triangle;
    bool operator<(const Entry& o) const { return key != o.key ? key < o.key : triangle < o.triangle; }
};

constexpr int kKeyBits = 21;
constexpr std::int64_t kCellsPerAxis = std::int64_t{1} << kKeyBits;
constexpr std::int64_t kMaxCells = 512; ///< a triangle spanning more cells goes to a coarser level

class GeometryCheck {
public:
    GeometryCheck(const Mesh& mesh, const MeshGeometryOptions& options) : mesh_(mesh), options_(options)
    {
        threads_ = thread_count(options.threads);
    }

    MeshGeometry run()
    {
        validate();
        weld();
        classify_triangles();
        test_all_levels();
        release_search();
        Mesh welded = welded_mesh();
        std::vector<std::uint32_t>().swap(welded_id_);
        std::vector<Point3>().swap(points_);
        result_.welded = mesh_topology(welded);
        return result_;
    }

private:
    void validate() const
    {
        const auto& tri = mesh_.triangles;
        if (tri.size() % 3 != 0) {
            throw Error(Status::invalid_argument, "mesh_geometry: the triangle array holds " + std::to_string(tri.size()) +
                                                      " indices; expected a multiple of 3");
        }
        if (tri.size() / 3 >= std::numeric_limits<std::uint32_t>::max()) {
            throw Error(Status::too_large, "mesh_geometry: too many triangles for 32-bit indices");
        }
        const std::size_t n = mesh_.vertex_count();
        for (std::size_t i = 0; i < tri.size(); ++i) {
            if (tri[i] >= n) {
                throw Error(Status::invalid_argument, "mesh_geometry: triangle " + std::to_string(i / 3) + " uses vertex " +
                                                          std::to_string(tri[i]) + " but the mesh has " +
                                                          std::to_string(n) + " vertices");
            }
        }
        for (std::size_t i = 0; i < mesh_.positions.size(); ++i) {
            if (!std::isfinite(mesh_.positions[i])) {
                throw Error(Status::invalid_argument, "mesh_geometry: vertex " + std::to_string(i / 3) +
                                                          " has a coordinate that is not a finite number");
            }
        }
    }

    Point3 position(std::uint32_t v) const
    {
        const float* p = &mesh_.positions[3 * static_cast<std::size_t>(v)];
        // + 0.0 turns -0 into +0, so that both weld to one position
        return {static_cast<double>(p[0]) + 0.0, static_cast<double>(p[1]) + 0.0, static_cast<double>(p[2]) + 0.0};
    }

    void weld()
    {
        const std::size_t n = mesh_.vertex_count();
        std::vector<std::uint32_t> order;
        {
            std::vector<std::uint8_t> used(n, 0);
            for (std::uint32_t v : mesh_.triangles) used[v] = 1;
            order.reserve(static_cast<std::size_t>(std::count(used.begin(), used.end(), std::uint8_t{1})));
            for (std::size_t v = 0; v < n; ++v)
                if (used[v]) order.push_back(static_cast<std::uint32_t>(v));
        }
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            const Point3 pa = position(a), pb = position(b);
            return pa != pb ? pa < pb : a < b;
        });
        welded_id_.assign(n, 0);
        points_.clear();
        points_.reserve(order.size()); // at most one position per used vertex, without growing past it
        for (std::size_t i = 0; i < order.size();) {
            std::size_t j = i + 1;
            const Point3 p = position(order[i]);
            while (j < order.size() && position(order[j]) == p) ++j;
            const auto id = static_cast<std::uint32_t>(points_.size());
            points_.push_back(p);
            for (std::size_t k = i; k < j; ++k) welded_id_[order[k]] = id;
            if (j - i > 1) result_.coincident_vertices += static_cast<std::int64_t>(j - i);
            i = j;
        }
        result_.positions = static_cast<std::int64_t>(points_.size());
    }

    std::array<std::uint32_t, 3> corners(std::size_t t) const
    {
        const auto& tri = mesh_.triangles;
        return {welded_id_[tri[3 * t]], welded_id_[tri[3 * t + 1]], welded_id_[tri[3 * t + 2]]};
    }

    void classify_triangles()
    {
        const std::size_t count = mesh_.triangle_count();
        proper_.assign(count, 0);
        std::vector<std::int64_t> zero(static_cast<std::size_t>(threads_), 0);
        detail::parallel_chunks(static_cast<std::int64_t>(count), threads_, [&](int th, std::int64_t t0, std::int64_t t1) {
            for (std::int64_t t = t0; t < t1; ++t) {
                const auto c = corners(static_cast<std::size_t>(t));
                const bool degenerate = c[0] == c[1] || c[1] == c[2] || c[0] == c[2] ||
                                        detail::collinear(points_[c[0]], points_[c[1]], points_[c[2]]);
                if (degenerate) {
                    ++zero[static_cast<std::size_t>(th)];
                } else {
                    proper_[static_cast<std::size_t>(t)] = 1;
                }
            }
        });
        for (auto z : zero) result_.zero_area_triangles += z;
    }

    Box box_of(std::size_t t) const
    {
        const auto c = corners(t);
        Box b{points_[c[0]], points_[c[0]]};
        for (int i = 1; i < 3; ++i)
            for (std::size_t k = 0; k < 3; ++k) {
                b.lo[k] = std::min(b.lo[k], points_[c[static_cast<std::size_t>(i)]][k]);
                b.hi[k] = std::max(b.hi[k], points_[c[static_cast<std::size_t>(i)]][k]);
            }
        return b;
    }

    std::array<std::int64_t, 3> cell_of(const Point3& p) const
    {
        std::array<std::int64_t, 3> c{};
        for (std::size_t k = 0; k < 3; ++k) {
            const double x = std::floor((p[k] - origin_[k]) / cell_);
            c[k] = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::fmin(x, 4.0 * kCellsPerAxis)), 0,
                                            kCellsPerAxis - 1);
        }
        return c;
    }

    static std::uint64_t key_of(const std::array<std::int64_t, 3>& c)
    {
        return static_cast<std::uint64_t>(c[0]) | static_cast<std::uint64_t>(c[1]) << kKeyBits |
               static_cast<std::uint64_t>(c[2]) << (2 * kKeyBits);
    }

    /// Boxes of the proper triangles, and the box around all of them. False if there is none.
    bool compute_boxes()
    {
        const std::size_t count = mesh_.triangle_count();
        boxes_.resize(count);
        level_.assign(count, -1);
        bool any = false;
        for (std::size_t t = 0; t < count; ++t) {
            if (!proper_[t]) continue;
            const Box b = box_of(t);
            boxes_[t] = b;
            if (!any) {
                origin_ = b.lo;
                top_ = b.hi;
                any = true;
            }
            for (std::size_t k = 0; k < 3; ++k) {
                origin_[k] = std::min(origin_[k], b.lo[k]);
                top_[k] = std::max(top_[k], b.hi[k]);
            }
        }
        return any;
    }

    static double extent_of(const Box& b) { return std::max({b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]}); }

    /// Grid levels for triangles of very different sizes: level L's cell is twice the 90th
    /// percentile of the extents of the triangles not yet placed; a triangle whose box spans at
    /// most kMaxCells cells takes level L. Level L's buckets hold every triangle of levels <= L, and
    /// its pairs are those with at least one triangle of level L, so each pair is tested at one
    /// level, and a large triangle among small ones costs the small ones it overlaps, not a
    /// bucket per cell of its box.
    void test_all_levels()
    {
        if (!compute_boxes()) return;
        std::vector<std::uint32_t> unplaced;
        for (std::size_t t = 0; t < proper_.size(); ++t)
            if (proper_[t]) unplaced.push_back(static_cast<std::uint32_t>(t));
        std::vector<std::uint32_t> placed;
        placed.reserve(unplaced.size());
        for (int level = 0; !unplaced.empty(); ++level) {
            {
                std::vector<double> extents(unplaced.size());
                for (std::size_t i = 0; i < unplaced.size(); ++i) extents[i] = extent_of(boxes_[unplaced[i]]);
                const std::size_t p90 = extents.size() * 9 / 10;
                std::nth_element(extents.begin(), extents.begin() + static_cast<std::ptrdiff_t>(p90), extents.end());
                cell_ = 2 * extents[p90];
            }
            for (std::size_t k = 0; k < 3; ++k)
                cell_ = std::max(cell_, (top_[k] - origin_[k]) / static_cast<double>(kCellsPerAxis - 2));
            if (!(cell_ > 0)) cell_ = 1;
            std::vector<std::uint32_t> rest;
            for (std::uint32_t t : unplaced) {
                const auto c0 = cell_of(boxes_[t].lo), c1 = cell_of(boxes_[t].hi);
                const std::int64_t cells = (c1[0] - c0[0] + 1) * (c1[1] - c0[1] + 1) * (c1[2] - c0[2] + 1);
                if (cells <= kMaxCells) {
                    level_[t] = level;
                    placed.push_back(t);
                } else {
                    rest.push_back(t);
                }
            }
            unplaced = std::move(rest);
            bucket(placed);
            test_pairs(level);
        }
        merge_examples();
    }

    void bucket(const std::vector<std::uint32_t>& triangles)
    {
        // counted first: growing the array by doubling held up to three times its size at once
        std::size_t count = 0;
        for (std::uint32_t t : triangles) {
            const auto c0 = cell_of(boxes_[t].lo), c1 = cell_of(boxes_[t].hi);
            count += static_cast<std::size_t>((c1[0] - c0[0] + 1) * (c1[1] - c0[1] + 1) * (c1[2] - c0[2] + 1));
        }
        if (entries_.capacity() < count) std::vector<Entry>().swap(entries_);
        entries_.clear();
        entries_.reserve(count);
        for (std::uint32_t t : triangles) {
            const auto c0 = cell_of(boxes_[t].lo), c1 = cell_of(boxes_[t].hi);
            for (std::int64_t z = c0[2]; z <= c1[2]; ++z)
                for (std::int64_t y = c0[1]; y <= c1[1]; ++y)
                    for (std::int64_t x = c0[0]; x <= c1[0]; ++x) entries_.push_back({key_of({x, y, z}), t});
        }
        std::sort(entries_.begin(), entries_.end());
        groups_.clear();
        for (std::size_t i = 0; i < entries_.size();) {
            std::size_t j = i + 1;
            while (j < entries_.size() && entries_[j].key == entries_[i].key) ++j;
            if (j - i > 1) groups_.push_back(i);
            i = j;
        }
        groups_.push_back(entries_.size());
    }

    /// Whether triangles a and b meet improperly; corners are welded ids.
    bool pair_meets(std::uint32_t ta, std::uint32_t tb) const
    {
        auto a = corners(ta), b = corners(tb);
        // put shared corners first, in the same order in both
        int shared = 0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                if (a[static_cast<std::size_t>(i)] != b[static_cast<std::size_t>(j)] || i < shared || j < shared) continue;
                std::swap(a[static_cast<std::size_t>(shared)], a[static_cast<std::size_t>(i)]);
                std::swap(b[static_cast<std::size_t>(shared)], b[static_cast<std::size_t>(j)]);
                ++shared;
                break;
            }
        if (shared == 3) return true; // the same triangle twice
        const std::array<Point3, 3> pa{points_[a[0]], points_[a[1]], points_[a[2]]};
        const std::array<Point3, 3> pb{points_[b[0]], points_[b[1]], points_[b[2]]};
        return detail::triangles_meet_improperly(pa, pb, shared);
    }

    /// Tests the pairs of level `level` (at least one of its triangles of that level) in every
    /// bucket, each pair once: in the bucket of the low corner of the two boxes' overlap.
    void test_pairs(int level)
    {
        const auto group_count = static_cast<std::int64_t>(groups_.size() - 1);
        found_.resize(static_cast<std::size_t>(threads_), 0);
        examples_.resize(static_cast<std::size_t>(threads_));
        detail::parallel_chunks(group_count, threads_, [&](int th, std::int64_t g0, std::int64_t g1) {
            auto& mine = examples_[static_cast<std::size_t>(th)];
            std::vector<std::uint32_t> top, all;
            for (std::int64_t g = g0; g < g1; ++g) {
                const std::size_t begin = groups_[static_cast<std::size_t>(g)];
                std::size_t end = begin + 1;
                while (end < entries_.size() && entries_[end].key == entries_[begin].key) ++end;
                top.clear();
                all.clear();
                for (std::size_t i = begin; i < end; ++i) {
                    all.push_back(entries_[i].triangle);
                    if (level_[entries_[i].triangle] == level) top.push_back(entries_[i].triangle);
                }
                for (std::uint32_t ta : top)
                    for (std::uint32_t tb : all) {
                        if (tb == ta || (level_[tb] == level && tb < ta)) continue; // each pair once
                        const Box &ba = boxes_[ta], &bb = boxes_[tb];
                        if (!boxes_overlap(ba, bb)) continue;
                        const Point3 low{std::max(ba.lo[0], bb.lo[0]), std::max(ba.lo[1], bb.lo[1]),
                                         std::max(ba.lo[2], bb.lo[2])};
                        if (key_of(cell_of(low)) != entries_[begin].key) continue;
                        if (!pair_meets(ta, tb)) continue;
                        ++found_[static_cast<std::size_t>(th)];
                        mine.push_back({std::min<std::int64_t>(ta, tb), std::max<std::int64_t>(ta, tb)});
                        if (mine.size() > 4 * options_.examples + 64) {
                            std::sort(mine.begin(), mine.end());
                            mine.resize(options_.examples);
                        }
                    }
            }
        });
    }

    void merge_examples()
    {
        std::vector<std::array<std::int64_t, 2>> all;
        for (std::size_t t = 0; t < found_.size(); ++t) {
            result_.intersecting_pairs += found_[t];
            all.insert(all.end(), examples_[t].begin(), examples_[t].end());
        }
        std::sort(all.begin(), all.end());
        if (all.size() > options_.examples) all.resize(options_.examples);
        result_.intersection_examples = std::move(all);
    }

    /// Frees the arrays of the pair search, before the welded mesh and its topology are made.
    void release_search()
    {
        std::vector<std::uint8_t>().swap(proper_);
        std::vector<Box>().swap(boxes_);
        std::vector<int>().swap(level_);
        std::vector<Entry>().swap(entries_);
        std::vector<std::size_t>().swap(groups_);
    }

    Mesh welded_mesh() const
    {
        Mesh w;
        w.positions.resize(3 * points_.size());
        for (std::size_t i = 0; i < points_.size(); ++i)
            for (std::size_t k = 0; k < 3; ++k) w.positions[3 * i + k] = static_cast<float>(points_[i][k]);
        w.triangles.resize(mesh_.triangles.size());
        for (std::size_t i = 0; i < mesh_.triangles.size(); ++i) w.triangles[i] = welded_id_[mesh_.triangles[i]];
        return w;
    }

    const Mesh& mesh_;
    MeshGeometryOptions options_;
    int threads_ = 1;
    MeshGeometry result_;
    std::vector<std::uint32_t> welded_id_;
    std::vector<Point3> points_;
    std::vector<std::uint8_t> proper_;
    std::vector<Box> boxes_;
    std::vector<int> level_; ///< grid level of each proper triangle (test_all_levels)
    Point3 origin_{}, top_{};
    double cell_ = 1;
    std::vector<Entry> entries_;
    std::vector<std::size_t> groups_; ///< start of every bucket with two or more entries, then the end
    std::vector<std::int64_t> found_; ///< intersecting pairs found, per thread
    std::vector<std::vector<std::array<std::int64_t, 2>>> examples_; ///< the smallest of them, per thread
};

} // namespace

MeshGeometry mesh_geometry(const Mesh& mesh, const MeshGeometryOptions& options)
{
    return GeometryCheck(mesh, options).run();
}

} // namespace cmc33
