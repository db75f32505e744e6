// The random fields of the stress test (contract in src/verify/include/cmc33/verify.hpp).
//
// Every item has its own SplitMix64 generator (Steele, Lea and Flood 2014), seeded from
// (seed, kind, n) through the generator's own finalizer, so a field is a pure function of those
// three numbers: runs are reproducible whatever the thread count, and `cmc33 dataset` and
// `cmc33 verify` with one seed draw the same fields.
//
// Cells. Uniform values (the paper's Sec. 4) rarely produce the subcases that need an interior
// test: a tunnel needs the values of one sign to dominate those of the other in a specific way.
// Cell n uses distribution n % 8 (below); the sign-pattern distributions take their configuration
// from n / 8 % 256, so every 2048 consecutive cells visit all 256 configurations at least twice.
// tests/verify checks that 20,000 cells reach every one of the 33 subcases of cmc33.

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"
#include "cmc33/verify.hpp"

namespace cmc33 {
namespace {

constexpr std::uint64_t kGolden = 0x9e3779b97f4a7c15ull;

constexpr std::uint64_t mix64(std::uint64_t z) noexcept
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

class SplitMix64 {
public:
    explicit SplitMix64(std::uint64_t state) : state_(state) {}
    std::uint64_t next() noexcept { return mix64(state_ += kGolden); }
    /// Uniform in [0, 1), 53 random bits.
    double unit() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
    double uniform(double lo, double hi) noexcept { return lo + (hi - lo) * unit(); }
    /// Uniform in {0, ..., n - 1} (n small: the bias of the modulo is below 2^-56).
    unsigned below(unsigned n) noexcept { return static_cast<unsigned>(next() % n); }

private:
    std::uint64_t state_;
};

SplitMix64 item_generator(FieldKind kind, std::int64_t n, std::uint64_t seed)
{
    const std::uint64_t key =
        (static_cast<std::uint64_t>(kind) + 1) << 56 ^ static_cast<std::uint64_t>(n);
    return SplitMix64(mix64(seed ^ mix64(key * kGolden)));
}

// Base case of every configuration, to draw configurations of the ambiguous cases. Taken from
// analyze_cell on +-1 values: which configurations a distribution favours has no influence on
// what the verifier expects (field_topology reads the samples only).
struct CaseLists {
    std::array<int, 256> base_case{};
    std::vector<unsigned> ambiguous; // base cases 3 4 6 7 10 12 13
    std::vector<unsigned> by_case[15];
};

const CaseLists& case_lists()
{
    static const CaseLists lists = [] {
        CaseLists l;
        for (unsigned config = 0; config < 256; ++config) {
            std::array<double, 8> v{};
            for (int c = 0; c < 8; ++c)
                v[static_cast<std::size_t>(c)] = (config >> c & 1u) ? 1.0 : -1.0;
            const int base = analyze_cell(v, 0.0, Method::cmc33).base_case;
            l.base_case[config] = base;
            l.by_case[base].push_back(config);
            if (base == 3 || base == 4 || base == 6 || base == 7 || base == 10 || base == 12 ||
                base == 13) {
                l.ambiguous.push_back(config);
            }
        }
        return l;
    }();
    return lists;
}

unsigned pick(SplitMix64& rng, const std::vector<unsigned>& configs)
{
    return configs[rng.below(static_cast<unsigned>(configs.size()))];
}

using Corners = std::array<double, 8>;

template <class F> Corners each_corner(F&& value)
{
    Corners v{};
    for (double& x : v) x = value();
    return v;
}

/// Values with the signs of `config` (bit set: above, >= 0) and magnitudes from `above`, `below`.
template <class A, class B> Corners signed_values(unsigned config, A&& above, B&& below)
{
    Corners v{};
    for (int c = 0; c < 8; ++c)
        v[static_cast<std::size_t>(c)] = (config >> c & 1u) ? above() : -below();
    return v;
}

/// Corners of one sign near a common level: the above ones level * (1 + spread * U[-1, 1]), the
/// below ones the same around level * exp(ratio * U[-1/2, 1/2]). Face and body saddles then sit
/// near the isovalue, where the decisions are close.
Corners near_levels(SplitMix64& rng, unsigned config, double ratio, double spread)
{
    const double up = rng.uniform(0.1, 1.0);
    const double down = up * std::exp(ratio * rng.uniform(-0.5, 0.5));
    return signed_values(
        config, [&] { return up * (1 + spread * rng.uniform(-1, 1)); },
        [&] { return down * (1 + spread * rng.uniform(-1, 1)); });
}

constexpr std::array<std::string_view, 8> kCellDistributions = {
    "uniform",       // 0: U[-1, 1], the paper's distribution
    "cubed",         // 1: U[-1, 1]^3: many values near 0, so saddles near the isovalue
    "pattern",       // 2: configuration n / 8 % 256, magnitudes U[0.05, 1]
    "diagonal",      // 3: two diagonal corners strongly of one sign, the rest weakly of the other
    "case13",        // 4: a case-13 configuration, magnitudes near one level (13.5 needs them)
    "tunnel-cubed",  // 5: a case 6, 10 or 12 configuration, magnitudes U[0.1, 1]^3
    "near-levels",   // 6: an ambiguous configuration, magnitudes near one level
    "pattern-cubed", // 7: configuration n / 8 % 256, magnitudes U[0.37, 1]^3 * U[0.2, 1]
};

// Measured with analyze_cell over 20,000 cells of each case (seed 1): magnitudes near one level
// give 13.5.2 about 3% of case-13 cells (log-uniform ones 0.5%); U[0.1, 1]^3 gives 10.1.2, 6.1.2
// and 12.1.2 about 3% of their cases (near-level ones almost never).
Corners random_cell(std::int64_t n, std::uint64_t seed)
{
    SplitMix64 rng = item_generator(FieldKind::cell, n, seed);
    const CaseLists& lists = case_lists();
    const auto pattern = static_cast<unsigned>((n / 8) % 256);
    switch (n % 8) {
    case 0:
        return each_corner([&] { return rng.uniform(-1, 1); });
    case 1:
        return each_corner([&] {
            const double u = rng.uniform(-1, 1);
            return u * u * u;
        });
    case 2:
        return signed_values(
            pattern, [&] { return rng.uniform(0.05, 1); }, [&] { return rng.uniform(0.05, 1); });
    case 3: {
        // Case 4 (and 6 with a neighbour): a main diagonal strong, the other corners weak and of
        // the other sign; a tunnel joins the strong corners unless the weak ones win.
        const unsigned a = rng.below(4), b = a ^ 7u;
        unsigned config = (1u << a) | (1u << b);
        if (rng.below(4) == 0) config |= 1u << (a ^ (1u << rng.below(3)));
        if (rng.below(2) == 0) config ^= 0xffu;
        auto strong = [&] { return rng.uniform(0.5, 1); };
        auto weak = [&] { return rng.uniform(0.01, 0.4); };
        return (config >> a & 1u) ? signed_values(config, strong, weak)
                                  : signed_values(config, weak, strong);
    }
    case 4:
        return near_levels(rng, rng.below(2) ? 0x69u : 0x96u, 0.2, 0.3);
    case 5: {
        static constexpr int kTunnelCases[3] = {6, 10, 12};
        const unsigned config = pick(rng, lists.by_case[kTunnelCases[rng.below(3)]]);
        auto cubed = [&] {
            const double u = rng.uniform(0.1, 1);
            return u * u * u;
        };
        return signed_values(config, cubed, cubed);
    }
    case 6:
        return near_levels(rng, pick(rng, lists.ambiguous), 0.4, 0.3);
    default: {
        const double scale = rng.uniform(0.2, 1);
        auto cubed = [&] {
            const double u = rng.uniform(0.37, 1); // 0.37^3 ~ 0.05
            return scale * u * u * u;
        };
        return signed_values(pattern, cubed, cubed);
    }
    }
}

void check_item(std::int64_t n)
{
    if (n < 1)
        throw Error(Status::invalid_argument,
                    "random field number " + std::to_string(n) + " is out of range; expected >= 1");
}

} // namespace

std::string_view field_kind_name(FieldKind kind) noexcept
{
    switch (kind) {
    case FieldKind::cell:
        return "cell";
    case FieldKind::grid:
        return "grid";
    case FieldKind::closed:
        return "closed";
    case FieldKind::ties:
        break;
    }
    return "ties";
}

std::string_view cell_distribution_name(std::int64_t n) noexcept
{
    return kCellDistributions[static_cast<std::size_t>(((n % 8) + 8) % 8)];
}

std::string field_name(FieldKind kind, std::int64_t n)
{
    std::string digits = std::to_string(n);
    if (digits.size() < 6) digits.insert(0, 6 - digits.size(), '0');
    return std::string(field_kind_name(kind)) + "-" + digits;
}

Volume random_field(FieldKind kind, std::int64_t n, std::uint64_t seed, int size)
{
    check_item(n);
    if (kind == FieldKind::cell) {
        const Corners v = random_cell(n, seed);
        Volume volume(ScalarType::f32, {2, 2, 2});
        float* out = volume.samples<float>();
        for (int c = 0; c < 8; ++c) out[c] = static_cast<float>(v[static_cast<std::size_t>(c)]);
        return volume;
    }
    const int min_size = kind == FieldKind::closed ? 3 : 2;
    if (size < min_size || size > 1024) {
        throw Error(Status::invalid_argument, "random " + std::string(field_kind_name(kind)) +
                                                  " size " + std::to_string(size) +
                                                  " is out of range; expected " +
                                                  std::to_string(min_size) + " to 1024");
    }
    SplitMix64 rng = item_generator(kind, n, seed);
    Volume volume(ScalarType::f32, {size, size, size});
    float* out = volume.samples<float>();
    const int last = size - 1;
    for (int k = 0; k < size; ++k) {
        for (int j = 0; j < size; ++j) {
            for (int i = 0; i < size; ++i) {
                const bool boundary =
                    i == 0 || j == 0 || k == 0 || i == last || j == last || k == last;
                double value = kind == FieldKind::closed && boundary ? rng.uniform(-1, -0.1) : rng.uniform(-1, 1);
                if (kind == FieldKind::ties) {
                    const unsigned half = n % 2 == 1 ? 2 : 3; // 0..4 at iso 2, 0..6 at iso 3
                    value = static_cast<double>(rng.below(2 * half + 1)) - half;
                }
                *out++ = static_cast<float>(value);
            }
        }
    }
    return volume;
}

} // namespace cmc33
