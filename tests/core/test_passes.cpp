// The public passes of passes.hpp: any split of the sample planes into ranges, with any first ids
// and each range writing only its slice of caller-owned arrays, gives extract()'s mesh byte for
// byte; the per-vertex and per-triangle extras say where each element came from; views with any
// strides and windows; blocks placed in a larger grid; misuse refused. Progress, cancellation,
// threads and range plans: test_passes_scheduling.cpp.

#include <array>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/passes.hpp"
#include "passes_fields.hpp"
#include "test_support.hpp"

namespace {

using cmc33::ExtractOptions;
using cmc33::GridView;
using cmc33::Method;
using cmc33::MeshSpans;
using cmc33::RangeCounts;
using cmc33::RangeOffsets;
using cmc33::Volume;
using cmc33::test::bucky;
using cmc33::test::noise;

/// The output of a split run: arrays for the global ids [first_vertex, first_vertex + n).
struct Output {
    std::int64_t first_vertex = 0, first_triangle = 0;
    std::vector<float> positions, normals, parameters, values, ranges;
    std::vector<std::uint32_t> triangles;
    std::vector<std::int64_t> edges, cells;
};

/// How emit writes (MeshSpans::zyx, reverse_winding), and whether the extras other than
/// vertex_cell_ranges are asked for (without them and with zyx: cmc33.marching_cubes's output).
struct Layout {
    bool zyx = false, reverse_winding = false, other_extras = true;
};

/// count / scan / emit over the ranges [b[r], b[r + 1]), each range given only its slice of the
/// output (element 0 of its arrays is its own first vertex and triangle). `windowed`: each pass of
/// each range reads the range's window() (one buffer, reused), not g.
template <class T>
Output run_split(const GridView<T>& g, double iso, const ExtractOptions& opt, const std::vector<std::int64_t>& b,
                 std::int64_t first_vertex = 0, std::int64_t first_triangle = 0, Layout layout = {},
                 bool windowed = false)
{
    cmc33::Buffer<T> buffer;
    const auto grid = [&](std::size_t r) { return windowed ? cmc33::window(g, b[r], b[r + 1], buffer) : g; };
    std::vector<RangeCounts> counts;
    for (std::size_t r = 0; r + 1 < b.size(); ++r) counts.push_back(cmc33::count(grid(r), iso, opt, b[r], b[r + 1]));
    const std::vector<RangeOffsets> offsets = cmc33::scan(counts, first_vertex, first_triangle);
    Output o;
    o.first_vertex = first_vertex, o.first_triangle = first_triangle;
    std::int64_t nv = 0, nt = 0;
    for (const RangeCounts& c : counts) nv += c.vertex_count(), nt += c.triangle_count();
    const auto v = static_cast<std::size_t>(nv), t = static_cast<std::size_t>(nt);
    o.positions.assign(3 * v, NAN), o.normals.assign(3 * v, NAN), o.parameters.assign(v, NAN), o.values.assign(v, NAN);
    o.ranges.assign(v, NAN);
    o.triangles.assign(3 * t, 0xdeadbeef), o.edges.assign(v, -7), o.cells.assign(t, -7);
    for (std::size_t r = 0; r < counts.size(); ++r) {
        const auto dv = static_cast<std::size_t>(offsets[r].first_vertex - first_vertex);
        const auto dt = static_cast<std::size_t>(offsets[r].first_triangle - first_triangle);
        MeshSpans s;
        s.positions = o.positions.data() + 3 * dv;
        s.normals = opt.normals ? o.normals.data() + 3 * dv : nullptr;
        s.vertex_parameters = o.parameters.data() + dv;
        s.vertex_values = o.values.data() + dv;
        s.vertex_edges = o.edges.data() + dv;
        s.triangles = o.triangles.data() + 3 * dt;
        s.triangle_cells = o.cells.data() + dt;
        s.vertex_cell_ranges = o.ranges.data() + dv;
        if (!layout.other_extras) {
            s.vertex_parameters = nullptr, s.vertex_values = nullptr, s.vertex_edges = nullptr;
            s.triangle_cells = nullptr;
        }
        s.zyx = layout.zyx;
        s.reverse_winding = layout.reverse_winding;
        s.first_vertex = offsets[r].first_vertex;
        s.first_triangle = offsets[r].first_triangle;
        cmc33::emit(grid(r), iso, opt, counts[r], offsets[r], s);
    }
    return o;
}

void expect_same_mesh(const cmc33::Mesh& m, const Output& o, const std::string& what)
{
    ASSERT_EQ(m.positions.size(), o.positions.size()) << what;
    ASSERT_EQ(m.triangles.size(), o.triangles.size()) << what;
    EXPECT_TRUE(std::equal(m.positions.begin(), m.positions.end(), o.positions.begin())) << what;
    if (!m.normals.empty()) {
        EXPECT_TRUE(std::equal(m.normals.begin(), m.normals.end(), o.normals.begin())) << what;
    }
    bool same = true;
    for (std::size_t i = 0; i < m.triangles.size(); ++i)
        same = same && std::int64_t{m.triangles[i]} + o.first_vertex == std::int64_t{o.triangles[i]};
    EXPECT_TRUE(same) << what << ": triangles differ";
}

/// Splits of nz planes: one range, three uneven ones, one plane each, the two-range splits at
/// every plane boundary, and seven uneven ones.
std::vector<std::vector<std::int64_t>> splits(std::int64_t nz)
{
    std::vector<std::vector<std::int64_t>> s = {{0, nz}, {0, 1, nz / 3 + 1, nz}};
    std::vector<std::int64_t> each;
    for (std::int64_t k = 0; k <= nz; ++k) each.push_back(k);
    s.push_back(each);
    for (std::int64_t k = 1; k < nz; ++k) s.push_back({0, k, nz});
    if (nz >= 8) {
        std::vector<std::int64_t> seven = {0}; // seven uneven ranges, short ones first
        for (std::int64_t r = 1; r < 7; ++r) seven.push_back(std::max(seven.back() + 1, nz * r * r / 49));
        seven.push_back(nz);
        s.push_back(seven);
    }
    return s;
}

TEST(Passes, AnySplitAndAnyFirstIdsGiveExtractsMesh)
{
    struct Case {
        Volume volume;
        double iso;
    };
    std::vector<Case> cases;
    cases.push_back({bucky(), 100.5});
    cases.push_back({bucky(), 100.0}); // ties on integer data
    cases.push_back({noise({11, 9, 13}, 5), 0.0});
    for (const Case& c : cases) {
        for (const Method method : {Method::cmc33, Method::mc33_lewiner, Method::mc}) {
            ExtractOptions opt;
            opt.method = method;
            opt.normals = true;
            opt.threads = 1;
            const cmc33::Mesh m = cmc33::extract(c.volume, c.iso, opt);
            ASSERT_GT(m.triangle_count(), 100u);
            for (const auto& b : splits(c.volume.dims()[2])) {
                for (const auto& ids : {std::pair<std::int64_t, std::int64_t>{0, 0}, {1000003, 77}}) {
                    const std::int64_t fv = ids.first, ft = ids.second; // not bindings: clang 14 lambdas
                    const std::string what = std::string(cmc33::method_name(method)) + " iso " + std::to_string(c.iso) +
                                             " ranges " + std::to_string(b.size() - 1) + " from " + std::to_string(b[1]) +
                                             " ids from " + std::to_string(fv);
                    const Output o = c.volume.visit([&](auto view) { return run_split(view, c.iso, opt, b, fv, ft); });
                    expect_same_mesh(m, o, what);
                    if (testing::Test::HasFailure()) return;
                }
            }
        }
    }
}

TEST(Passes, ExtractWithAnyThreadCountIsTheCompositionOfThePasses)
{
    const Volume v = noise({20, 17, 23}, 9);
    ExtractOptions opt;
    opt.normals = true;
    opt.threads = 1;
    const cmc33::Mesh one = cmc33::extract(v, 0.1, opt);
    for (const int threads : {2, 3, 7, 23, 64}) {
        opt.threads = threads;
        const cmc33::Mesh m = cmc33::extract(v, 0.1, opt);
        EXPECT_EQ(m.positions, one.positions) << threads;
        EXPECT_EQ(m.normals, one.normals) << threads;
        EXPECT_EQ(m.triangles, one.triangles) << threads;
    }
}

/// Checks the extras of a split run on g; adds its interior vertices to `interior`.
template <class T>
void check_extras(const GridView<T>& g, double iso, const std::vector<std::int64_t>& splits, std::int64_t& interior)
{
    const Output o = run_split(g, iso, ExtractOptions{}, splits);
    const std::int64_t nx = g.nx(), ny = g.ny();
    const std::size_t nv = o.edges.size();
    for (std::size_t i = 0; i < nv; ++i) {
        const std::int64_t e = o.edges[i];
        ASSERT_NE(e, -7) << "vertex " << i << " not written";
        if (e < 0) {
            ++interior;
            EXPECT_EQ(o.parameters[i], -1.0f);
            continue;
        }
        const std::int64_t axis = e % 3, s = e / 3;
        const std::int64_t p[3] = {s % nx, s / nx % ny, s / (nx * ny)};
        const float t = o.parameters[i];
        ASSERT_GT(t, 0.0f) << i;
        ASSERT_LT(t, 1.0f) << i;
        for (int c = 0; c < 3; ++c) {
            const double expected = static_cast<double>(p[c]) + (c == axis ? static_cast<double>(t) : 0.0);
            EXPECT_NEAR(o.positions[3 * i + static_cast<std::size_t>(c)], expected, 1e-5) << i;
        }
        std::int64_t q[3] = {p[0], p[1], p[2]};
        ++q[axis];
        const auto a = static_cast<double>(g(p[0], p[1], p[2])), b = static_cast<double>(g(q[0], q[1], q[2]));
        ASSERT_TRUE((a >= iso) != (b >= iso)) << "vertex " << i << " on an edge that does not cross";
        EXPECT_NEAR(o.values[i], a + static_cast<double>(t) * (b - a), 1e-3) << i;
    }
    // every triangle lies in its cell, and an interior vertex's cell is that of its triangles;
    // a vertex's cell range is the largest of its triangles' cells'
    std::vector<double> largest_range(nv, 0.0);
    for (std::size_t t = 0; t < o.cells.size(); ++t) {
        const std::int64_t c = o.cells[t];
        ASSERT_GE(c, 0);
        const std::int64_t corner[3] = {c % nx, c / nx % ny, c / (nx * ny)};
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (int q = 0; q < 8; ++q) {
            const auto value = static_cast<double>(g(corner[0] + (q & 1), corner[1] + (q >> 1 & 1), corner[2] + (q >> 2)));
            lo = std::min(lo, value), hi = std::max(hi, value);
        }
        for (int q = 0; q < 3; ++q) {
            const std::size_t vtx = o.triangles[3 * t + static_cast<std::size_t>(q)];
            largest_range[vtx] = std::max(largest_range[vtx], hi - lo);
        }
        for (int q = 0; q < 3; ++q) {
            const std::size_t vtx = o.triangles[3 * t + static_cast<std::size_t>(q)];
            ASSERT_LT(vtx, nv);
            for (std::size_t a = 0; a < 3; ++a) {
                EXPECT_GE(o.positions[3 * vtx + a], static_cast<float>(corner[a]));
                EXPECT_LE(o.positions[3 * vtx + a], static_cast<float>(corner[a] + 1));
            }
            if (o.edges[vtx] < 0) {
                EXPECT_EQ(-1 - o.edges[vtx], c);
            }
        }
    }
    for (std::size_t i = 0; i < nv; ++i) ASSERT_EQ(o.ranges[i], static_cast<float>(largest_range[i])) << "vertex " << i;
}

TEST(Passes, TheExtrasSayWhereEveryVertexAndTriangleCameFrom)
{
    const Volume b = bucky(), n = noise({12, 11, 13}, 21);
    std::int64_t interior = 0;
    check_extras(b.view<std::uint8_t>(), 100.0, {0, 9, 20, 32}, interior); // ties
    check_extras(n.view<double>(), 0.0, {0, 4, 5, 13}, interior);
    EXPECT_GT(interior, 0) << "no interior vertex checked";
}

/// Samples of type T from a seeded noise, quantized to a few levels for integers (ties).
template <class T> std::vector<T> typed_noise(cmc33::Index3 dims, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<T> v(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
    for (T& x : v) x = static_cast<T>(std::is_integral_v<T> ? std::round(20 * u(rng)) + (std::is_signed_v<T> ? 0 : 40) : u(rng));
    return v;
}

TEST(Passes, TheDropInsOutputIsTheExtrasRangesAndPositionsInZyx)
{
    // cmc33.marching_cubes's outputs (positions and normals in (z, y, x), vertex_cell_ranges and
    // nothing else): the same numbers as with every extra, which check_extras checks, for 8-,
    // 16- and 32-bit and float samples, rows long enough for the cell ranges' groups of 8 cells
    // and their ends, and views whose x is not the contiguous axis
    std::int64_t interior = 0;
    const auto check = [&](auto tag, double iso) {
        using T = decltype(tag);
        const cmc33::Index3 dims = {21, 10, 13};
        const std::vector<T> samples = typed_noise<T>(dims, 17);
        const GridView<T> dense = GridView<T>::dense(samples.data(), dims);
        // the same samples with x and z swapped: x is the slow axis
        const GridView<T> swapped{samples.data(), {dims[2], dims[1], dims[0]}, {dims[0] * dims[1], dims[0], 1}};
        ExtractOptions opt;
        opt.normals = true;
        for (const GridView<T>& g : {dense, swapped}) {
            for (const std::vector<std::int64_t>& b : {std::vector<std::int64_t>{0, g.nz()}, {0, 4, 5, g.nz()}}) {
                check_extras(g, iso, b, interior);
                const Output all = run_split(g, iso, opt, b);
                const Output drop_in = run_split(g, iso, opt, b, 0, 0, Layout{true, false, false});
                ASSERT_EQ(drop_in.positions.size(), all.positions.size());
                for (std::size_t i = 0; i < all.positions.size(); i += 3) {
                    for (std::size_t c = 0; c < 3; ++c) {
                        ASSERT_EQ(drop_in.positions[i + 2 - c], all.positions[i + c]) << i;
                        ASSERT_EQ(drop_in.normals[i + 2 - c], all.normals[i + c]) << i;
                    }
                }
                EXPECT_EQ(drop_in.ranges, all.ranges);
                EXPECT_EQ(drop_in.triangles, all.triangles);
            }
        }
    };
    check(std::uint8_t{}, 40.5);
    check(std::int16_t{}, 0.0);
    check(std::uint16_t{}, 40.0);
    check(std::int32_t{}, -0.5);
    check(float{}, 0.0);
    check(double{}, 0.25);
    EXPECT_GT(interior, 0) << "no interior vertex checked";
}

TEST(Passes, ZyxAndReversedWindingOnlyPermuteTheOutput)
{
    const Volume v = noise({9, 7, 12}, 3);
    ExtractOptions opt;
    opt.normals = true;
    const std::vector<std::int64_t> b = {0, 5, 12};
    v.visit([&](auto view) {
        const Output plain = run_split(view, 0.05, opt, b);
        for (const Layout layout : {Layout{true, false}, Layout{false, true}, Layout{true, true}}) {
            const Output o = run_split(view, 0.05, opt, b, 0, 0, layout);
            for (std::size_t i = 0; i < plain.positions.size(); i += 3) {
                for (std::size_t c = 0; c < 3; ++c) {
                    const std::size_t to = i + (layout.zyx ? 2 - c : c);
                    ASSERT_EQ(o.positions[to], plain.positions[i + c]);
                    ASSERT_EQ(o.normals[to], plain.normals[i + c]);
                }
            }
            for (std::size_t t = 0; t < plain.triangles.size(); t += 3) {
                ASSERT_EQ(o.triangles[t], plain.triangles[t]);
                ASSERT_EQ(o.triangles[t + 1], plain.triangles[t + (layout.reverse_winding ? 2 : 1)]);
                ASSERT_EQ(o.triangles[t + 2], plain.triangles[t + (layout.reverse_winding ? 1 : 2)]);
            }
            EXPECT_EQ(o.ranges, plain.ranges);
        }
    });
}

TEST(Passes, ViewsWithAnyStridesAreReadInPlace)
{
    const Volume v = bucky();
    const GridView<std::uint8_t> dense = v.view<std::uint8_t>();
    const std::int64_t nx = dense.nx(), ny = dense.ny(), nz = dense.nz();
    ExtractOptions opt;
    opt.normals = true;
    opt.threads = 2;
    const cmc33::Mesh expected = cmc33::extract(dense, 100.0, opt);

    // the same samples stored in Fortran order reversed (i slowest): strides (ny nz, nz, 1)
    std::vector<std::uint8_t> fortran(static_cast<std::size_t>(nx * ny * nz));
    for (std::int64_t k = 0; k < nz; ++k)
        for (std::int64_t j = 0; j < ny; ++j)
            for (std::int64_t i = 0; i < nx; ++i) fortran[static_cast<std::size_t>(k + nz * (j + ny * i))] = dense(i, j, k);
    GridView<std::uint8_t> f = dense;
    f.data = fortran.data();
    f.strides = {ny * nz, nz, 1};
    const cmc33::Mesh mf = cmc33::extract(f, 100.0, opt);
    EXPECT_EQ(mf.positions, expected.positions);
    EXPECT_EQ(mf.normals, expected.normals);
    EXPECT_EQ(mf.triangles, expected.triangles);

    // every axis stored backwards: negative strides, data at the sample (0, 0, 0) of the view
    std::vector<std::uint8_t> backwards(fortran.size());
    for (std::int64_t k = 0; k < nz; ++k)
        for (std::int64_t j = 0; j < ny; ++j)
            for (std::int64_t i = 0; i < nx; ++i)
                backwards[static_cast<std::size_t>((nx - 1 - i) + nx * ((ny - 1 - j) + ny * (nz - 1 - k)))] = dense(i, j, k);
    GridView<std::uint8_t> r = dense;
    r.data = backwards.data() + (backwards.size() - 1);
    r.strides = {-1, -nx, -nx * ny};
    const cmc33::Mesh mr = cmc33::extract(r, 100.0, opt);
    EXPECT_EQ(mr.positions, expected.positions);
    EXPECT_EQ(mr.triangles, expected.triangles);

    // every other sample along x and y (a numpy vol[::2, ::2, :] view) against a dense copy of it
    GridView<std::uint8_t> sub = dense;
    sub.dims = {nx / 2, ny / 2, nz};
    sub.strides = {2, 2 * nx, nx * ny};
    Volume copy(cmc33::ScalarType::u8, sub.dims);
    for (std::int64_t k = 0; k < nz; ++k)
        for (std::int64_t j = 0; j < sub.ny(); ++j)
            for (std::int64_t i = 0; i < sub.nx(); ++i)
                copy.samples<std::uint8_t>()[i + sub.nx() * (j + sub.ny() * k)] = sub(i, j, k);
    const cmc33::Mesh ms = cmc33::extract(sub, 100.0, opt), mc = cmc33::extract(copy, 100.0, opt);
    ASSERT_GT(ms.triangle_count(), 100u);
    EXPECT_EQ(ms.positions, mc.positions);
    EXPECT_EQ(ms.normals, mc.normals);
    EXPECT_EQ(ms.triangles, mc.triangles);
    // and through the passes, split
    expect_same_mesh(mc, run_split(sub, 100.0, opt, {0, 5, 6, nz}), "strided split");
}

TEST(Passes, WindowsGiveTheSameBytesAsTheGridForEverySplit)
{
    // a double field stored in Fortran order (x slowest), with a non-identity frame
    const cmc33::Index3 dims{9, 7, 11};
    const Volume v = noise(dims, 17);
    const GridView<double> dense = v.view<double>();
    std::vector<double> fortran(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
    for (std::int64_t k = 0; k < dims[2]; ++k)
        for (std::int64_t j = 0; j < dims[1]; ++j)
            for (std::int64_t i = 0; i < dims[0]; ++i)
                fortran[static_cast<std::size_t>(k + dims[2] * (j + dims[1] * i))] = dense(i, j, k);
    GridView<double> f = dense;
    f.data = fortran.data();
    f.strides = {dims[1] * dims[2], dims[2], 1};
    f.spacing = {0.5, 2, 1.25};
    f.origin = {-3, 1e3, 7};
    EXPECT_EQ(cmc33::window_range_planes(dense), 0);
    EXPECT_GE(cmc33::window_range_planes(f), 1);
    EXPECT_EQ(cmc33::window_range_planes(f, 1), 1);
    ExtractOptions opt;
    opt.normals = true;
    opt.threads = 1;
    GridView<double> framed = dense;
    framed.spacing = f.spacing, framed.origin = f.origin;
    const cmc33::Mesh expected = cmc33::extract(framed, 0.1, opt);
    ASSERT_GT(expected.triangle_count(), 100u);
    for (const auto& split : splits(dims[2])) {
        std::string name = "windows of split";
        for (std::int64_t b : split) name += " " + std::to_string(b);
        const Output o = run_split(f, 0.1, opt, split, 0, 0, {}, true), plain = run_split(framed, 0.1, opt, split);
        expect_same_mesh(expected, o, name);
        // and the extras (every one is written: no NaN left)
        EXPECT_EQ(o.ranges, plain.ranges) << name;
        EXPECT_EQ(o.values, plain.values) << name;
        EXPECT_EQ(o.parameters, plain.parameters) << name;
        EXPECT_EQ(o.edges, plain.edges) << name;
        EXPECT_EQ(o.cells, plain.cells) << name;
    }
    // extract() reads such a grid through windows, whatever the thread count
    for (const int threads : {1, 2, 3}) {
        opt.threads = threads;
        const cmc33::Mesh m = cmc33::extract(f, 0.1, opt);
        EXPECT_EQ(m.positions, expected.positions) << threads;
        EXPECT_EQ(m.normals, expected.normals) << threads;
        EXPECT_EQ(m.triangles, expected.triangles) << threads;
    }
    cmc33::Buffer<double> buffer;
    for (const auto& [k0, k1] : {std::pair<std::int64_t, std::int64_t>{-1, 3}, {3, 3}, {5, 12}}) {
        EXPECT_THROW(cmc33::window(f, k0, k1, buffer), cmc33::Error) << k0 << " " << k1;
    }
}

/// window() of every range of a grid of T with dimensions `dims` laid out with strides `order` (the
/// axis of each stride rank: {2, 1, 0} is Fortran order) holds each sample of the planes the range
/// reads.
template <class T> void expect_windows_hold_the_samples(std::array<int, 3> order, cmc33::Index3 dims)
{
    std::vector<T> samples(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
    GridView<T> g;
    g.data = samples.data();
    g.dims = dims;
    std::int64_t stride = 1;
    for (const int axis : order) g.strides[static_cast<std::size_t>(axis)] = stride, stride *= dims[static_cast<std::size_t>(axis)];
    for (std::int64_t k = 0; k < dims[2]; ++k)
        for (std::int64_t j = 0; j < dims[1]; ++j)
            for (std::int64_t i = 0; i < dims[0]; ++i)
                samples[static_cast<std::size_t>(g.offset(i, j, k))] = static_cast<T>((i * 7 + j * 31 + k * 11) % 120 - 50);
    cmc33::Buffer<T> buffer;
    for (std::int64_t k0 = 0; k0 < dims[2]; ++k0)
        for (std::int64_t k1 = k0 + 1; k1 <= dims[2]; ++k1) {
            const GridView<T> w = cmc33::window(g, k0, k1, buffer);
            bool same = true;
            for (std::int64_t k = std::max<std::int64_t>(k0 - 1, 0); k <= std::min(k1 + 1, dims[2] - 1); ++k)
                for (std::int64_t j = 0; j < dims[1]; ++j)
                    for (std::int64_t i = 0; i < dims[0]; ++i) same = same && w(i, j, k) == g(i, j, k);
            EXPECT_TRUE(same) << "[" << k0 << ", " << k1 << ") of " << sizeof(T) << "-byte samples, strides ranked "
                              << order[0] << order[1] << order[2];
            EXPECT_EQ(w.strides[0], 1);
        }
}

TEST(Passes, WindowsHoldTheSamplesOfEveryTypeAndLayout)
{
    for (const std::array<int, 3> order : {std::array<int, 3>{2, 1, 0}, {1, 2, 0}, {1, 0, 2}, {0, 1, 2}}) {
        // not multiples of a tile (8 bytes, or a cache line); then several tiles along x and the
        // rows fetched ahead of them
        for (const cmc33::Index3 dims : {cmc33::Index3{13, 5, 19}, cmc33::Index3{70, 9, 21}}) {
            expect_windows_hold_the_samples<std::int8_t>(order, dims);
            expect_windows_hold_the_samples<std::uint16_t>(order, dims);
            expect_windows_hold_the_samples<float>(order, dims);
            expect_windows_hold_the_samples<double>(order, dims);
        }
    }
}

/// The status f() throws, or nullopt when it returns.
/// count and emit over the whole of `g` with the extras, placed at `offset` in a grid of `whole`
/// samples (MeshSpans::index_offset, whole_dims; zero: g itself).
Output run_placed(const GridView<double>& g, double iso, cmc33::Index3 offset, cmc33::Index3 whole)
{
    const ExtractOptions opt;
    const RangeCounts c = cmc33::count(g, iso, opt, 0, g.nz());
    Output o;
    const auto nv = static_cast<std::size_t>(c.vertex_count()), nt = static_cast<std::size_t>(c.triangle_count());
    o.positions = std::vector<float>(3 * nv), o.normals = std::vector<float>(3 * nv);
    o.edges = std::vector<std::int64_t>(nv), o.cells = std::vector<std::int64_t>(nt);
    o.triangles = std::vector<std::uint32_t>(3 * nt);
    MeshSpans out;
    out.positions = o.positions.data(), out.normals = o.normals.data(), out.triangles = o.triangles.data();
    out.vertex_edges = o.edges.data(), out.triangle_cells = o.cells.data();
    out.index_offset = offset, out.whole_dims = whole;
    cmc33::emit(g, iso, opt, c, {}, out);
    return o;
}

/// Per vertex a key in the whole grid: its edge, or for an interior vertex -1 - (32 cell + rank).
std::vector<std::int64_t> vertex_keys(const Output& o)
{
    std::vector<std::int64_t> keys(o.edges.size());
    std::int64_t previous = 0, rank = 0;
    for (std::size_t v = 0; v < keys.size(); ++v) {
        const std::int64_t e = o.edges[v];
        rank = e < 0 && v > 0 && e == previous ? rank + 1 : 0;
        previous = e;
        keys[v] = e >= 0 ? e : -1 - (32 * (-1 - e) + rank);
    }
    return keys;
}

TEST(Passes, ABlockPlacedInTheWholeGridWritesTheWholesVerticesBitForBit)
{
    // far from the origin, where crossings keep 2^-8 / 0.75 of an edge from the samples in the
    // whole grid's box (z to 2055) and half that in the block's own (z to 2045): the whole's
    // margin must be taken; an anisotropic spacing, and a frame that is not diagonal
    const Volume n = noise({23, 19, 21}, 5);
    const cmc33::Mat3 rotated{{{0.6, -0.8, 0}, {0.8, 0.6, 0}, {0, 0, 1}}};
    for (const cmc33::Mat3& direction : {cmc33::kIdentity3, rotated}) {
        GridView<double> whole = n.view<double>();
        whole.spacing = {0.75, 1.25, 2.0}, whole.origin = {1500.0, -900.25, 2015.0}, whole.direction = direction;
        const Output w = run_placed(whole, 0.0, {0, 0, 0}, {0, 0, 0});
        const std::vector<std::int64_t> wkeys = vertex_keys(w);
        std::map<std::int64_t, std::size_t> at;
        for (std::size_t v = 0; v < wkeys.size(); ++v) at[wkeys[v]] = v;
        std::map<std::int64_t, std::vector<std::int64_t>> tiles; // cell -> its triangles' keys
        for (std::size_t t = 0; t < w.cells.size(); ++t)
            for (std::size_t q = 0; q < 3; ++q) tiles[w.cells[t]].push_back(wkeys[w.triangles[3 * t + q]]);

        const cmc33::Index3 offset{5, 4, 6}, dims{9, 8, 10};
        GridView<double> block = whole;
        block.data = whole.data + whole.offset(offset[0], offset[1], offset[2]);
        block.dims = dims;
        const Output b = run_placed(block, 0.0, offset, whole.dims);
        const std::vector<std::int64_t> bkeys = vertex_keys(b);
        EXPECT_TRUE(std::any_of(b.edges.begin(), b.edges.end(), [](std::int64_t e) { return e < 0; })) << "no interior vertex";
        std::size_t inner = 0;
        for (std::size_t v = 0; v < bkeys.size(); ++v) {
            const auto found = at.find(bkeys[v]);
            ASSERT_NE(found, at.end()) << "block vertex " << v << " key " << bkeys[v];
            for (std::size_t c = 0; c < 3; ++c) {
                EXPECT_EQ(std::bit_cast<std::uint32_t>(b.positions[3 * v + c]),
                          std::bit_cast<std::uint32_t>(w.positions[3 * found->second + c]))
                    << "vertex " << v << " coordinate " << c;
            }
            // normals: equal where the edge's ends have their neighbours inside the block
            const std::int64_t e = b.edges[v] >= 0 ? b.edges[v] / 3 : -1 - b.edges[v];
            const std::int64_t g[3] = {e % whole.nx(), e / whole.nx() % whole.ny(), e / (whole.nx() * whole.ny())};
            bool inside = true;
            for (std::size_t c = 0; c < 3; ++c) inside &= g[c] - offset[c] >= 1 && g[c] - offset[c] + 2 < dims[c];
            if (!inside) continue;
            ++inner;
            for (std::size_t c = 0; c < 3; ++c) {
                EXPECT_EQ(std::bit_cast<std::uint32_t>(b.normals[3 * v + c]),
                          std::bit_cast<std::uint32_t>(w.normals[3 * found->second + c]))
                    << "normal of vertex " << v;
            }
        }
        EXPECT_GT(inner, 50u);
        std::map<std::int64_t, std::vector<std::int64_t>> block_tiles;
        for (std::size_t t = 0; t < b.cells.size(); ++t)
            for (std::size_t q = 0; q < 3; ++q) block_tiles[b.cells[t]].push_back(bkeys[b.triangles[3 * t + q]]);
        ASSERT_FALSE(block_tiles.empty());
        for (const auto& [cell, keys] : block_tiles) EXPECT_EQ(keys, tiles[cell]) << "cell " << cell;
    }
}

TEST(Passes, TheWholeGridPlacedInItselfWritesWhatItWritesUnplaced)
{
    // far from the origin (a margin wider than 2^-10), in a frame that is not diagonal
    const Volume n = noise({17, 13, 15}, 9);
    GridView<double> g = n.view<double>();
    g.spacing = {0.75, 1.25, 2.0}, g.origin = {1500.0, -900.25, 2015.0};
    g.direction = {{{0.6, -0.8, 0}, {0.8, 0.6, 0}, {0, 0, 1}}};
    const Output unplaced = run_placed(g, 0.0, {0, 0, 0}, {0, 0, 0});
    const Output placed = run_placed(g, 0.0, {0, 0, 0}, g.dims);
    ASSERT_FALSE(unplaced.triangles.empty());
    const auto bits = [](const std::vector<float>& v) {
        std::vector<std::uint32_t> b(v.size());
        std::transform(v.begin(), v.end(), b.begin(), [](float x) { return std::bit_cast<std::uint32_t>(x); });
        return b;
    };
    EXPECT_EQ(bits(placed.positions), bits(unplaced.positions));
    EXPECT_EQ(bits(placed.normals), bits(unplaced.normals));
    EXPECT_EQ(placed.triangles, unplaced.triangles);
    EXPECT_EQ(placed.edges, unplaced.edges);
    EXPECT_EQ(placed.cells, unplaced.cells);
}

template <class F> std::optional<cmc33::Status> status_of(F&& f)
{
    try {
        f();
    } catch (const cmc33::Error& e) {
        return e.status();
    }
    return std::nullopt;
}

TEST(Passes, MisuseIsRefusedBeforeAnyWrite)
{
    const Volume v = bucky();
    const GridView<std::uint8_t> g = v.view<std::uint8_t>();
    const ExtractOptions opt;
    using cmc33::Status;
    for (const auto& range : {std::pair<std::int64_t, std::int64_t>{-1, 3}, {3, 3}, {5, 2}, {0, 33}}) {
        const std::int64_t k0 = range.first, k1 = range.second;
        EXPECT_EQ(status_of([&] { (void)cmc33::count(g, 100.5, opt, k0, k1); }), Status::invalid_argument) << k0 << " " << k1;
    }
    const RangeCounts a = cmc33::count(g, 100.5, opt, 0, 10), b = cmc33::count(g, 100.5, opt, 11, 32);
    const std::vector<RangeCounts> gap = {a, b};
    EXPECT_EQ(status_of([&] { (void)cmc33::scan(gap); }), Status::invalid_argument);

    // counts of another grid
    GridView<std::uint8_t> smaller = g;
    smaller.dims = {32, 31, 32};
    std::vector<float> positions(3 * static_cast<std::size_t>(a.vertex_count()) + 3, -1.0f);
    std::vector<std::uint32_t> triangles(3 * static_cast<std::size_t>(a.triangle_count()) + 3, 7u);
    MeshSpans out;
    out.positions = positions.data();
    out.triangles = triangles.data();
    EXPECT_EQ(status_of([&] { cmc33::emit(smaller, 100.5, opt, a, {}, out); }), Status::invalid_argument);
    MeshSpans none;
    EXPECT_EQ(status_of([&] { cmc33::emit(g, 100.5, opt, a, {}, none); }), Status::invalid_argument);

    // counts of another isovalue or method: refused, and nothing written past the range's arrays
    // (the guard element at the end of each)
    for (const double other : {90.5, 100.0, 140.5}) {
        EXPECT_EQ(status_of([&] { cmc33::emit(g, other, opt, a, {}, out); }), Status::invalid_argument) << other;
        EXPECT_EQ(positions.back(), -1.0f) << other;
        EXPECT_EQ(triangles.back(), 7u) << other;
    }
    ExtractOptions mc = opt;
    mc.method = cmc33::Method::mc;
    EXPECT_EQ(status_of([&] { cmc33::emit(g, 100.5, mc, a, {}, out); }), Status::invalid_argument);
    // samples changed between the passes: refused when emit meets other crossings than count
    // counted, and nothing written outside the range's arrays either way
    Volume changed = bucky();
    for (std::int64_t q = 0; q < changed.sample_count(); q += 7) changed.samples<std::uint8_t>()[q] ^= 0x55;
    const auto changed_status = status_of([&] { cmc33::emit(changed.view<std::uint8_t>(), 100.5, opt, a, {}, out); });
    EXPECT_EQ(changed_status, Status::internal);
    EXPECT_EQ(positions.back(), -1.0f);
    EXPECT_EQ(triangles.back(), 7u);
    cmc33::emit(g, 100.5, opt, a, {}, out); // the right counts: fine
    RangeOffsets huge;
    huge.first_vertex = 4294967000;
    EXPECT_EQ(status_of([&] { cmc33::emit(g, 100.5, opt, a, huge, out); }), Status::too_large);
    // a block's place in a larger grid: inside it, and an offset only with the larger grid's dims
    for (const auto& [offset, whole] : {std::pair<cmc33::Index3, cmc33::Index3>{{1, 0, 0}, {0, 0, 0}},
                                        {{1, 0, 0}, {32, 32, 32}},
                                        {{-1, 0, 0}, {40, 40, 40}},
                                        {{0, 0, 9}, {40, 40, 40}}}) {
        MeshSpans placed = out;
        placed.index_offset = offset, placed.whole_dims = whole;
        EXPECT_EQ(status_of([&] { cmc33::emit(g, 100.5, opt, a, {}, placed); }), Status::invalid_argument)
            << offset[0] << " " << offset[2] << " " << whole[0];
    }
    MeshSpans placed = out;
    placed.index_offset = {8, 0, 8}, placed.whole_dims = {40, 32, 40};
    cmc33::emit(g, 100.5, opt, a, {}, placed); // inside: fine
}

} // namespace
