// cmc33 info: what a volume holds, and which isovalues are worth trying.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/volume.hpp"
#include "plane_reader.hpp"
#include "plural.hpp"
#include "slabs.hpp"
#include "commands.hpp"
#include "common.hpp"

namespace cmc33::cli {

namespace {

constexpr int kBins = 16;      // the histogram shown
constexpr int kFineBins = 4096; // the one quantiles and Otsu's threshold are read from

struct InfoArgs {
    std::string input;
    bool json = false;
    std::string memory_limit; ///< empty: the volume in memory
    RawVolumeOptions raw;
};

struct Histogram {
    double lo = 0, hi = 0;                 ///< value range of the finite samples
    std::array<std::int64_t, kBins> bins{};
    std::vector<std::int64_t> fine = std::vector<std::int64_t>(kFineBins, 0);
    std::vector<double> fine_min = std::vector<double>(kFineBins, 0); ///< smallest sample in each fine bin
    std::int64_t finite = 0;

    /// The value at x / n of the way from lo to hi. When hi - lo passes the double range
    /// (samples near +-1e308) it is weighted from both ends instead, which cannot overflow.
    double at(double x, int n) const
    {
        if (std::isfinite(hi - lo)) return lo + x * ((hi - lo) / n);
        const double f = x / n;
        return lo * (1 - f) + hi * f;
    }
    /// Where v lies between lo and hi, in [0, 1] (0 when they are equal).
    double fraction(double v) const
    {
        const double range = hi - lo;
        if (!(range > 0)) return 0.0;
        const double u = std::isfinite(range) ? (v - lo) / range : (0.5 * v - 0.5 * lo) / (0.5 * hi - 0.5 * lo);
        return u >= 0 ? std::min(u, 1.0) : 0.0; // NaN would become a bin index
    }
};

/// `n` samples of value v (finite) into the histogram.
void add(Histogram& h, double v, std::int64_t n)
{
    h.finite += n;
    const double u = h.fraction(v);
    h.bins[static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>(u * kBins)))] += n;
    const auto f = static_cast<std::size_t>(std::min(kFineBins - 1, static_cast<int>(u * kFineBins)));
    if (h.fine[f] == 0 || v < h.fine_min[f]) h.fine_min[f] = v;
    h.fine[f] += n;
}

template <class T> void fill(const T* samples, std::int64_t count, Histogram& h)
{
    for (std::int64_t i = 0; i < count; ++i) {
        const double v = static_cast<double>(samples[i]);
        if (std::isfinite(v)) add(h, v, 1);
    }
}

/// What info shows of a volume, from the volume in memory or read slab by slab.
struct Summary {
    Json volume;           ///< volume_json()
    Index3 dims{};
    ScalarType type = ScalarType::u8;
    Vec3 spacing{}, origin{};
    Mat3 direction = kIdentity3;
    std::string space;
    std::string frame_source; ///< Volume::frame_source()
    std::int64_t samples = 0;
    std::uint64_t bytes = 0;
    double lo = 0, hi = 0; ///< value_range()
    NonFinite bad;
    Histogram h;
};

Summary summarize(const std::string& path, const Volume& volume)
{
    Summary s;
    s.volume = volume_json(path, volume);
    s.dims = volume.dims();
    s.type = volume.type();
    s.spacing = volume.spacing(), s.origin = volume.origin(), s.direction = volume.direction(), s.space = volume.space();
    s.frame_source = volume.frame_source();
    s.samples = volume.sample_count();
    s.bytes = volume.byte_size();
    std::tie(s.lo, s.hi) = value_range(volume);
    s.bad = find_non_finite(volume);
    s.h.lo = s.lo, s.h.hi = s.hi;
    volume.visit([&](const auto& grid) { fill(grid.data, volume.sample_count(), s.h); });
    return s;
}

/// summarize() of a volume read a few planes at a time within `limit` bytes: samples of 8 and
/// 16 bits in one pass (a count per value, from which the range and the histogram follow), wider
/// ones in two (the range, then the histogram, whose bins depend on it).
Summary summarize_slabs(const std::string& path, const std::optional<io::RawOptions>& raw, std::uint64_t limit,
                        const RawVolumeOptions& options)
{
    io::detail::VolumeLayout layout = named_step(path, "reading the volume's header", [&] {
        return io::detail::describe_volume(path, raw, read_options(path, options));
    });
    apply_space(layout.grid.origin, layout.grid.direction, layout.grid.space, options, path);
    const io::detail::Grid& g = layout.grid;
    Summary s;
    s.volume = volume_json(path, g.dims, g.type, g.spacing, g.origin, g.direction, g.space);
    s.dims = g.dims;
    s.type = g.type;
    s.spacing = g.spacing, s.origin = g.origin, s.direction = g.direction, s.space = g.space;
    s.frame_source = g.frame_source;
    s.samples = g.dims[0] * g.dims[1] * g.dims[2];
    s.lo = std::numeric_limits<double>::infinity(), s.hi = -s.lo; // as value_range(): none finite yet
    s.bytes = static_cast<std::uint64_t>(s.samples) * type_size(g.type);
    const std::uint64_t plane = layout.plane_bytes();
    const std::int64_t nz = g.dims[2];
    const std::int64_t planes = std::clamp<std::int64_t>(static_cast<std::int64_t>(limit / 2 / std::max<std::uint64_t>(plane, 1)), 1, nz);
    std::vector<std::byte> buffer(static_cast<std::size_t>(static_cast<std::uint64_t>(planes) * plane));
    io::detail::PlaneReader reader(layout);
    const auto each_slab = [&](const auto& visit) {
        for (std::int64_t k = 0; k < nz; k += planes) {
            const std::int64_t k1 = std::min(nz, k + planes);
            named_step(path, "reading the volume", [&] { reader.read(k, k1, buffer.data()); });
            visit(k, (k1 - k) * g.dims[0] * g.dims[1]);
        }
    };
    dispatch_scalar_type(g.type, [&](auto tag) {
        using T = decltype(tag);
        const auto* data = reinterpret_cast<const T*>(buffer.data());
        if constexpr (sizeof(T) <= 2 && std::is_integral_v<T>) {
            std::vector<std::int64_t> counts(std::size_t{1} << (8 * sizeof(T)), 0);
            each_slab([&](std::int64_t, std::int64_t n) {
                for (std::int64_t i = 0; i < n; ++i) ++counts[static_cast<std::make_unsigned_t<T>>(data[i])];
            });
            for (std::size_t u = 0; u < counts.size(); ++u) {
                if (counts[u] == 0) continue;
                const double v = static_cast<double>(static_cast<T>(static_cast<std::make_unsigned_t<T>>(u)));
                s.lo = std::min(s.lo, v);
                s.hi = std::max(s.hi, v);
            }
            s.h.lo = s.lo, s.h.hi = s.hi;
            for (std::size_t u = 0; u < counts.size(); ++u) {
                if (counts[u] > 0) add(s.h, static_cast<double>(static_cast<T>(static_cast<std::make_unsigned_t<T>>(u))), counts[u]);
            }
        } else {
            each_slab([&](std::int64_t k, std::int64_t n) {
                for (std::int64_t i = 0; i < n; ++i) {
                    const double v = static_cast<double>(data[i]);
                    if (!std::isfinite(v)) {
                        if (s.bad.count++ == 0) {
                            const std::int64_t at = k * g.dims[0] * g.dims[1] + i;
                            s.bad.first = {at % g.dims[0], at / g.dims[0] % g.dims[1], at / (g.dims[0] * g.dims[1])};
                        }
                        continue;
                    }
                    s.lo = v < s.lo ? v : s.lo; // value_range()'s comparisons: the first of -0 and +0 stays
                    s.hi = v > s.hi ? v : s.hi;
                }
            });
            s.h.lo = s.lo, s.h.hi = s.hi;
            each_slab([&](std::int64_t, std::int64_t n) { fill(data, n, s.h); });
        }
    });
    return s;
}

/// The q-quantile of the finite samples, read from the fine histogram: the smallest sample of the
/// bin that holds it. Exact when each bin holds one distinct value (integer data with a range below
/// 4096), else within a bin width below it.
double quantile(const Histogram& h, double q)
{
    const double target = std::max(1.0, std::ceil(q * static_cast<double>(h.finite)));
    double seen = 0;
    for (std::size_t b = 0; b < h.fine.size(); ++b) {
        seen += static_cast<double>(h.fine[b]);
        if (seen >= target) return h.fine_min[b];
    }
    return h.hi;
}

/// Otsu's threshold: the value that splits the samples into two classes of largest between-class
/// variance; for a scan of an object in air it is the object's surface.
double otsu(const Histogram& h)
{
    double total = 0, total_sum = 0;
    for (int b = 0; b < kFineBins; ++b) {
        total += static_cast<double>(h.fine[static_cast<std::size_t>(b)]);
        total_sum += b * static_cast<double>(h.fine[static_cast<std::size_t>(b)]);
    }
    double w0 = 0, sum0 = 0, best = -1;
    int best_b = 0;
    for (int b = 0; b + 1 < kFineBins; ++b) {
        w0 += static_cast<double>(h.fine[static_cast<std::size_t>(b)]);
        sum0 += b * static_cast<double>(h.fine[static_cast<std::size_t>(b)]);
        const double w1 = total - w0;
        if (w0 == 0 || w1 == 0) continue;
        const double m0 = sum0 / w0, m1 = (total_sum - sum0) / w1;
        const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
        if (between > best) best = between, best_b = b;
    }
    return h.at(best_b + 1, kFineBins); // the upper edge of the lower class
}

/// Centres of the histogram's local maxima, the most populated first.
std::vector<int> modes(const Histogram& h)
{
    std::vector<int> peaks;
    for (int b = 0; b < kBins; ++b) {
        const auto n = h.bins[static_cast<std::size_t>(b)];
        const auto left = b > 0 ? h.bins[static_cast<std::size_t>(b - 1)] : -1;
        const auto right = b + 1 < kBins ? h.bins[static_cast<std::size_t>(b + 1)] : -1;
        if (n > 0 && n > left && n >= right) peaks.push_back(b);
    }
    std::stable_sort(peaks.begin(), peaks.end(), [&](int a, int b) {
        return h.bins[static_cast<std::size_t>(a)] > h.bins[static_cast<std::size_t>(b)];
    });
    return peaks;
}

/// Significant digits that tell apart values `step` apart within [lo, hi] (at least `least`):
/// 1000 to 1000.009 in 16 bins needs 8, where 5 would print every edge as 1000.
int digits_for(double lo, double hi, double step, int least)
{
    const double magnitude = std::max(std::fabs(lo), std::fabs(hi));
    if (!(magnitude > 0)) return least; // all zero
    if (!(step > 0) || !std::isfinite(magnitude / step)) return 17; // a step below the values' ulp
    const int needed = static_cast<int>(std::ceil(std::log10(magnitude / step))) + 1;
    return std::clamp(needed, least, 17); // 17 digits name every double
}

/// A value for display and for --iso: an integer for integer samples, else the fewest significant
/// digits (4 or more) that keep it within a thousandth of the range; either way inside (lo, hi],
/// where an isovalue has samples on both sides (a sample equal to it counts as above).
double round_for(double value, const Histogram& h, ScalarType type)
{
    const double lo = h.lo, hi = h.hi;
    const auto inside = [&](double v) { return v > lo && v <= hi; };
    if (type != ScalarType::f32 && type != ScalarType::f64) {
        // lo and hi are integers here: the nearest integer above lo and at most hi
        return std::clamp(std::round(value), lo + 1, hi);
    }
    const double tolerance = std::isfinite(hi - lo) ? (hi - lo) / 1000 : 0.5 * hi / 1000 - 0.5 * lo / 1000;
    for (int digits = 4; digits <= 17; ++digits) {
        const double rounded = std::strtod(sig(value, digits).c_str(), nullptr);
        if (std::isfinite(rounded) && inside(rounded) && std::fabs(rounded - value) <= tolerance) return rounded;
    }
    if (inside(value)) return value;
    return value <= lo ? std::nextafter(lo, hi) : hi; // a range of a few ulps: the nearest double inside
}

struct Candidate {
    double value;
    std::string why;
};

std::vector<Candidate> candidates(const Histogram& h, ScalarType type)
{
    std::vector<Candidate> out;
    if (h.finite == 0 || !(h.hi > h.lo)) return out;
    out.push_back({round_for(otsu(h), h, type), "Otsu's threshold"});
    std::vector<int> peaks = modes(h);
    if (peaks.size() > 3) peaks.resize(3);
    std::sort(peaks.begin(), peaks.end());
    auto centre = [&](int b) { return h.at(b + 0.5, kBins); };
    const int digits = digits_for(h.lo, h.hi, h.at(1, kBins) - h.lo, 4);
    for (std::size_t i = 0; i + 1 < peaks.size(); ++i) {
        const double a = centre(peaks[i]), b = centre(peaks[i + 1]);
        out.push_back({round_for(0.5 * a + 0.5 * b, h, type),
                       "midway between the histogram modes near " + sig(a, digits) + " and " + sig(b, digits)});
    }
    return out;
}

std::string bar(std::int64_t n, std::int64_t largest)
{
    constexpr int kWidth = 40;
    if (n == 0 || largest == 0) return "";
    // log scale: volumes are mostly background, a linear bar would show only the background bin
    const double f = std::log1p(static_cast<double>(n)) / std::log1p(static_cast<double>(largest));
    return std::string(static_cast<std::size_t>(std::max(1.0, std::round(f * kWidth))), '#');
}

/// The frame beyond spacing and origin: the named space, and the direction of each axis when
/// they are not x, y, z themselves (docs/conventions.md).
void print_frame(const std::string& space, const Mat3& d, const std::string& source)
{
    if (!space.empty()) std::cout << "space " << space << '\n';
    if (!source.empty()) std::cout << "frame from " << source << '\n';
    if (d == kIdentity3) return;
    std::cout << "directions (world direction of +i, +j, +k):";
    for (std::size_t a = 0; a < 3; ++a) std::cout << " " << "ijk"[a] << " " << vec_text({d[0][a], d[1][a], d[2][a]});
    std::cout << (determinant(d) < 0 ? "; mirrored (det < 0): extract reverses the triangles' winding" : "") << '\n';
}

/// A DICOM input of several series: what each one is, for --series (one line each, or JSON).
/// False when the input is not DICOM or holds one series (read as a volume then).
bool list_dicom_series(const InfoArgs& args)
{
    if (!args.raw.series.empty() || !io::is_dicom_input(args.input)) return false;
    const std::vector<io::DicomSeries> list = named_step(args.input, "reading the DICOM headers", [&] { return io::dicom_series(args.input); });
    if (list.size() < 2) return false;
    if (args.json) {
        Json out = Json::array();
        for (const io::DicomSeries& s : list) {
            Json entry = {{"uid", s.uid}, {"description", s.description}, {"modality", s.modality},
                          {"dims", {s.dims[0], s.dims[1], s.dims[2]}},
                          {"spacing", {json_number(s.spacing[0]), json_number(s.spacing[1]), json_number(s.spacing[2])}},
                          {"files", s.files}};
            if (!s.problem.empty()) entry["problem"] = s.problem;
            out.push_back(entry);
        }
        std::cout << Json{{"file", args.input}, {"series", out}}.dump(2) << '\n';
        return true;
    }
    std::cout << args.input << ": " << list.size() << " DICOM series; read one with --series UID\n";
    for (const io::DicomSeries& s : list) {
        std::cout << "  " << s.uid << "  " << (s.modality.empty() ? "" : s.modality + " ")
                  << (s.description.empty() ? "(no description)" : "\"" + s.description + "\"") << "  " << dims_text(s.dims);
        if (s.problem.empty()) std::cout << "  spacing " << vec_text(s.spacing);
        std::cout << "  (" << counted(static_cast<std::int64_t>(s.files), "file") << ")";
        if (!s.problem.empty()) std::cout << "  not readable: " << s.problem;
        std::cout << '\n';
    }
    return true;
}

void run_info(const InfoArgs& args)
{
    if (list_dicom_series(args)) return;
    const Summary summary = args.memory_limit.empty()
                                ? summarize(args.input, load_volume(args.input, args.raw))
                                : summarize_slabs(args.input, raw_volume_options(args.input, args.raw),
                                                  slabs::parse_size(args.memory_limit), args.raw);
    const double lo = summary.lo, hi = summary.hi;
    const NonFinite& bad = summary.bad;
    const Histogram& h = summary.h;
    const std::vector<Candidate> cand = candidates(h, summary.type);
    const std::array<double, 5> qs{0.01, 0.25, 0.5, 0.75, 0.99};
    const bool has_values = h.finite > 0;
    // equal samples fill one bin [lo, lo]: 16 empty bins [lo, lo) would say nothing
    const int bin_count = !has_values ? 0 : hi > lo ? kBins : 1;

    if (args.json) {
        Json out = summary.volume;
        if (!summary.frame_source.empty()) out["frame_source"] = summary.frame_source;
        out["samples"] = summary.samples;
        out["min"] = has_values ? json_number(lo) : Json(nullptr);
        out["max"] = has_values ? json_number(hi) : Json(nullptr);
        out["non_finite"] = {{"count", bad.count},
                             {"first", bad.count > 0 ? Json{bad.first[0], bad.first[1], bad.first[2]} : Json(nullptr)}};
        Json bins = Json::array();
        for (int b = 0; b < bin_count; ++b) {
            bins.push_back({{"lo", h.at(b, kBins)},
                            {"hi", b + 1 == bin_count ? hi : h.at(b + 1, kBins)},
                            {"count", h.bins[static_cast<std::size_t>(b)]}});
        }
        out["histogram"] = bins;
        Json quantiles = Json::object();
        for (double q : qs) quantiles["p" + num(q * 100)] = has_values ? json_number(quantile(h, q)) : Json(nullptr);
        out["quantiles"] = quantiles;
        Json c = Json::array();
        for (const Candidate& x : cand) c.push_back({{"iso", x.value}, {"why", x.why}});
        out["candidate_isovalues"] = c;
        print_json(out);
        return;
    }
    std::cout << args.input << ": " << dims_text(summary.dims) << " " << type_name(summary.type) << " ("
              << counted(summary.samples, "sample") << ", " << counted(summary.bytes, "byte") << ")\n";
    std::cout << "spacing " << vec_text(summary.spacing) << ", origin " << vec_text(summary.origin) << '\n';
    print_frame(summary.space, summary.direction, summary.frame_source);
    if (!has_values) {
        std::cout << "no finite samples\n";
    } else {
        std::cout << "values " << num(lo) << " to " << num(hi) << '\n';
    }
    if (bad.count > 0) {
        std::cout << "non-finite samples: " << bad.count << " (NaN or infinite), the first at (" << bad.first[0]
                  << ", " << bad.first[1] << ", " << bad.first[2] << "); extract refuses this volume\n";
    }
    if (!has_values) return;
    // as many digits as tell the bins' edges apart: 1000 to 1000.009 is not 16 bins [1000, 1000)
    const int digits = digits_for(lo, hi, h.at(1, kBins) - lo, 5);
    const std::size_t width = static_cast<std::size_t>(std::max(11, digits + 7));
    if (bin_count == 1) {
        std::cout << "histogram: every finite sample is " << num(lo) << '\n';
    } else {
        std::cout << "histogram (" << kBins << " bins, bar length on a log scale):\n";
    }
    const std::int64_t largest = *std::max_element(h.bins.begin(), h.bins.end());
    const auto edge = [&](double v) {
        const std::string text = bin_count == 1 ? num(v) : sig(v, digits);
        return std::string(text.size() < width ? width - text.size() : 0, ' ') + text;
    };
    for (int b = 0; b < bin_count; ++b) {
        const double a = h.at(b, kBins), z = b + 1 == bin_count ? hi : h.at(b + 1, kBins);
        char count[32];
        std::snprintf(count, sizeof count, " %12lld  ", static_cast<long long>(h.bins[static_cast<std::size_t>(b)]));
        std::cout << "  [" << edge(a) << ", " << edge(z) << (b + 1 == bin_count ? ']' : ')') << count
                  << bar(h.bins[static_cast<std::size_t>(b)], largest) << '\n';
    }
    std::cout << "quantiles:";
    for (double q : qs) std::cout << " p" << num(q * 100) << " " << (bin_count == 1 ? num(lo) : sig(quantile(h, q), digits));
    std::cout << '\n';
    if (cand.empty()) {
        std::cout << "hint: every sample has the same value; there is no isosurface to extract\n";
        return;
    }
    std::cout << "hint: isovalues to try:";
    for (std::size_t i = 0; i < cand.size(); ++i) {
        std::cout << (i ? ";" : "") << " --iso " << num(cand[i].value) << " (" << cand[i].why << ")";
    }
    std::cout << '\n';
}

} // namespace

void add_info(CLI::App& app)
{
    auto args = std::make_shared<InfoArgs>();
    CLI::App* cmd = app.add_subcommand("info", "Describe a volume: dimensions, type, value range, histogram");
    cmd->add_option("INPUT", args->input, "Volume: .nrrd .nhdr .mhd .mha .vtk, or headerless raw with --dims/--type")
        ->required();
    cmd->add_flag("--json", args->json, "Print one JSON object");
    cmd->add_option("--memory-limit", args->memory_limit,
                    "Read the volume a few planes at a time within SIZE bytes (256M, 2G); the same output")
        ->type_name("SIZE")
        ->check(cli::memory_size());
    add_raw_volume_options(*cmd, args->raw);
    cmd->footer(
        "Reads INPUT and prints its dimensions, sample type, spacing and origin (and the axis\n"
        "directions and named space when the file gives them), the range of its\n"
        "values, how many samples are NaN or infinite (extract refuses those), a 16-bin histogram\n"
        "and some quantiles, then a hint with isovalues worth trying: Otsu's threshold (the value\n"
        "that best splits the samples in two classes, e.g. object and air) and the midpoints\n"
        "between the largest histogram modes. --json prints all of it as one object.\n"
        "--memory-limit reads the volume slab by slab (8- and 16-bit samples in one pass, wider ones\n"
        "in two: the range, then the histogram), for volumes larger than memory.\n"
        "\n"
        "Examples:\n"
        "  cmc33 info aneurism.nrrd\n"
        "  cmc33 info scan.raw --dims 512 512 300 --type int16 --json\n"
        "  cmc33 info scan_4096.nrrd --memory-limit 1G");
    cmd->callback([args] { run_info(*args); });
}

} // namespace cmc33::cli
