// The decision kernel's filters against exact arithmetic: decide() (128-bit integers where the
// values allow, else filtered doubles without eps terms, with them, and rationals) must give, for
// every cell, the decision of decide_in<mpq_class>, which computes every sign exactly. The cells are
// built to sit on and near the filters' edges: exact ties, dyadic and decimal values, values that
// differ in their last bits, tiny and huge magnitudes. The exact fallback of builds without GMP
// (decide_expansion: Shewchuk expansions on values scaled by a power of two) must give the
// rationals' decision on every one of them too.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "cmc33/error.hpp"
#include "decide.hpp"

namespace {

using cmc33::Method;
using cmc33::detail::Decision;

/// The exact decision: every sign in rational arithmetic, eps terms included.
Decision exact(const double* raw, double iso, unsigned config, Method method)
{
    double v[8];
    for (int q = 0; q < 8; ++q) v[q] = raw[q] - iso;
    return cmc33::detail::decide_in<mpq_class>(raw, iso, v, config, method, cmc33::detail::kVariants);
}

unsigned config_of(const double* raw, double iso)
{
    unsigned c = 0;
    for (int q = 0; q < 8; ++q) c |= static_cast<unsigned>(raw[q] >= iso) << q;
    return c;
}

/// Compares decide() with exact() on `cells` cells drawn by `draw`; returns how many had a test.
template <class Draw> int compare(Draw&& draw, double iso, int cells, std::uint64_t seed, const char* what)
{
    std::mt19937_64 rng(seed);
    int tested = 0;
    for (int n = 0; n < cells; ++n) {
        double raw[8];
        for (double& x : raw) x = draw(rng);
        const unsigned config = config_of(raw, iso);
        if (config == 0 || config == 255) continue;
        for (const Method method : {Method::cmc33, Method::chernyaev, Method::mc33_lewiner}) {
            const Decision got = cmc33::detail::decide(raw, iso, config, method);
            const Decision want = exact(raw, iso, config, method);
            double v[8];
            for (int q = 0; q < 8; ++q) v[q] = raw[q] - iso;
            const Decision expansion = cmc33::detail::decide_expansion(raw, iso, v, config, method);
            if (expansion.variant != want.variant || expansion.tiling != want.tiling || expansion.joined != want.joined) {
                ADD_FAILURE() << what << ", cell " << n << " (" << cmc33::method_name(method)
                              << "): decide_expansion gives subcase " << expansion.subcase << " tiling "
                              << expansion.tiling << ", exactly " << want.subcase << " tiling " << want.tiling;
                return tested;
            }
            if (got.variant != want.variant || got.tiling != want.tiling || got.subcase != want.subcase) {
                std::string values;
                for (const double x : raw) values += " " + std::to_string(x);
                ADD_FAILURE() << what << ", cell " << n << " (" << cmc33::method_name(method) << "), values" << values
                              << ", iso " << iso << ": subcase " << got.subcase << " tiling " << got.tiling
                              << ", exactly " << want.subcase << " tiling " << want.tiling;
                return tested;
            }
        }
        tested += cmc33::detail::kAmbiguousFaces[config] != 0;
    }
    return tested;
}

TEST(Decide, FilteredDecisionsAreTheExactOnes)
{
    // uniform floats: the no-eps filter decides nearly all
    EXPECT_GT(compare([](auto& r) { return std::uniform_real_distribution<double>(-1, 1)(r); }, 0.0, 20000, 1, "uniform"),
              5000);
    // floats rounded to float32, iso a float: the usual float volume
    EXPECT_GT(compare([](auto& r) { return static_cast<double>(static_cast<float>(std::uniform_real_distribution<double>(-1, 1)(r))); },
                      0.25, 20000, 2, "float32"),
              5000);
    // three integer values, iso the middle one: ties everywhere (integer path)
    compare([](auto& r) { return static_cast<double>(60 + 20 * static_cast<int>(r() % 3)); }, 80.0, 20000, 3, "ties");
    // the same as decimals, which are not dyadic: ties decided by the filters and rationals
    compare([](auto& r) { return 0.1 * static_cast<double>(static_cast<int>(r() % 5) - 2); }, 0.1, 20000, 4,
            "decimal ties");
    // values a few units in the last place apart around the isovalue: near-ties for the filters
    compare([](auto& r) {
        const double base = 0.3;
        return base + std::ldexp(static_cast<double>(static_cast<int>(r() % 9) - 4), -52);
    }, 0.3, 20000, 5, "last-bit differences");
    // a face whose saddle is within rounding of an isovalue that is not a double's exact sum (0.1):
    // B solves (A - iso)(C - iso) = (B - iso)(D - iso) in long double, then moves up to 4 units in
    // the last place, so that the exact sign of A C - B D is either and the rounding of fl(x - iso)
    // is as large as the difference
    for (int f = 0; f < 6; ++f) {
        std::mt19937_64 rng(100 + static_cast<std::uint64_t>(f));
        std::uniform_real_distribution<double> u(0.3, 1.0), any(-1.0, 1.0);
        const auto p = cmc33::detail::face_cycle(f);
        const double iso = 0.1;
        int cells = 0;
        for (int n = 0; n < 3000; ++n) {
            double raw[8];
            for (double& x : raw) x = iso + any(rng);
            raw[p[0]] = iso + u(rng), raw[p[2]] = iso + u(rng), raw[p[3]] = iso - u(rng);
            const auto l_iso = static_cast<long double>(iso);
            const auto l = [&](int q) { return static_cast<long double>(raw[p[static_cast<std::size_t>(q)]]); };
            double b = static_cast<double>(l_iso + (l(0) - l_iso) * (l(2) - l_iso) / (l(3) - l_iso));
            for (int step = static_cast<int>(rng() % 9); step > 0; --step) b = std::nextafter(b, rng() % 2 ? 1.0 : -1.0);
            raw[p[1]] = b;
            cells += compare([&, q = 0](auto&) mutable { return raw[q++]; }, iso, 1, 0, "near-singular face");
        }
        EXPECT_GT(cells, 2000) << "face " << f;
    }
    // products that underflow and overflow the filters' double range
    compare([](auto& r) { return std::ldexp(std::uniform_real_distribution<double>(-1, 1)(r), -530); }, 0.0, 5000, 6,
            "tiny");
    compare([](auto& r) { return std::ldexp(std::uniform_real_distribution<double>(-1, 1)(r), 500); }, 0.0, 5000, 7,
            "huge");
}

TEST(Decide, ExpansionFallbackRefusesWhatItCannotDecide)
{
    // An ambiguous face whose below corners are 2^-600 and above ones 1: the product of the below
    // pair, 2^-1200, underflows the expansions, so the fallback says so instead of deciding.
    const auto p = cmc33::detail::face_cycle(0);
    double raw[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
    raw[p[0]] = 1, raw[p[2]] = 1, raw[p[1]] = -0x1p-600, raw[p[3]] = -0x1p-600;
    const double iso = 0;
    const unsigned config = config_of(raw, iso);
    ASSERT_NE(cmc33::detail::kAmbiguousFaces[config] & 1u, 0u);
    double v[8];
    for (int q = 0; q < 8; ++q) v[q] = raw[q] - iso;
    try {
        (void)cmc33::detail::decide_expansion(raw, iso, v, config, Method::cmc33);
        ADD_FAILURE() << "decided a face whose products underflow";
    } catch (const cmc33::Error& e) {
        EXPECT_EQ(e.status(), cmc33::Status::internal);
        EXPECT_NE(std::string(e.what()).find("beyond this build's range"), std::string::npos) << e.what();
    }
    // Scaled to sit near 1, the same face at 2^-30 is decided, and as the rationals decide it.
    raw[p[1]] = -0x1p-30, raw[p[3]] = -0x1p-30;
    for (int q = 0; q < 8; ++q) v[q] = raw[q] - iso;
    const Decision d = cmc33::detail::decide_expansion(raw, iso, v, config, Method::cmc33);
    const Decision want = exact(raw, iso, config, Method::cmc33);
    EXPECT_EQ(d.variant, want.variant);
    EXPECT_EQ(d.joined, want.joined);
}

} // namespace
