// numpy arrays read in place, and their value range.

#include "binding.hpp"
#include "parallel.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

namespace cmc33::python {
namespace {

std::string dtype_text(const py::array& a)
{
    return py::str(static_cast<py::object>(a.dtype())).cast<std::string>();
}

std::optional<ScalarType> scalar_type(char kind, py::ssize_t size)
{
    switch (kind) {
    case 'b': return size == 1 ? std::optional(ScalarType::u8) : std::nullopt; // numpy bool: 0 or 1
    case 'i':
        if (size == 1) return ScalarType::i8;
        if (size == 2) return ScalarType::i16;
        if (size == 4) return ScalarType::i32;
        return std::nullopt;
    case 'u':
        if (size == 1) return ScalarType::u8;
        if (size == 2) return ScalarType::u16;
        if (size == 4) return ScalarType::u32;
        return std::nullopt;
    case 'f':
        if (size == 4) return ScalarType::f32;
        if (size == 8) return ScalarType::f64;
        return std::nullopt;
    default: return std::nullopt;
    }
}

bool native_order(char byteorder) noexcept
{
    // '=' native, '|' not applicable (one byte); '<' or '>' name an order, which may be the machine's
    constexpr char native = std::endian::native == std::endian::little ? '<' : '>';
    return byteorder == '=' || byteorder == '|' || byteorder == native;
}

/// Smallest and largest sample over the view, NaN skipped: the innermost loop runs along the
/// axis with the smallest stride, whatever the layout; the outermost axis is split among threads,
/// which stop early when control says so (Error{cancelled}).
template <class T> std::pair<double, double> range_of(const Samples& s, int threads, Control& control)
{
    std::array<int, 3> axes{0, 1, 2};
    std::sort(axes.begin(), axes.end(), [&](int a, int b) {
        return std::llabs(s.strides[static_cast<std::size_t>(a)]) < std::llabs(s.strides[static_cast<std::size_t>(b)]);
    });
    // an axis of stride 0 (np.broadcast_to) repeats its samples: one of them is enough
    const auto dim = [&](int a) {
        return s.strides[static_cast<std::size_t>(a)] == 0 ? std::min<std::int64_t>(s.dims[static_cast<std::size_t>(a)], 1)
                                                            : s.dims[static_cast<std::size_t>(a)];
    };
    const auto stride = [&](int a) { return s.strides[static_cast<std::size_t>(a)]; };
    const std::int64_t n0 = dim(axes[0]), n1 = dim(axes[1]), n2 = dim(axes[2]);
    const std::int64_t s0 = stride(axes[0]), s1 = stride(axes[1]), s2 = stride(axes[2]);
    const T* base = static_cast<const T*>(s.data);
    constexpr bool kFloat = std::is_floating_point_v<T>;
    constexpr T kLow = kFloat ? -std::numeric_limits<T>::infinity() : std::numeric_limits<T>::lowest();
    constexpr T kHigh = kFloat ? std::numeric_limits<T>::infinity() : std::numeric_limits<T>::max();

    // threads only pay off on large volumes (a thread costs about what 10^5 samples do)
    const int n = s.count() < (std::int64_t{1} << 20) ? 1 : detail::threads_for(threads, n2);
    std::vector<std::pair<T, T>> found(static_cast<std::size_t>(n), {kHigh, kLow});
    detail::parallel_chunks(n2, n, [&](int t, std::int64_t c0, std::int64_t c1) {
        T lo = kHigh, hi = kLow;
        for (std::int64_t c = c0; c < c1 && !control.stopped(); ++c)
            for (std::int64_t b = 0; b < n1; ++b) {
                const T* row = base + c * s2 + b * s1;
                if (s0 == 1) { // comparisons are false for NaN: it is skipped
                    for (std::int64_t a = 0; a < n0; ++a) {
                        lo = row[a] < lo ? row[a] : lo;
                        hi = row[a] > hi ? row[a] : hi;
                    }
                } else {
                    for (std::int64_t a = 0; a < n0; ++a) {
                        const T v = row[a * s0];
                        lo = v < lo ? v : lo;
                        hi = v > hi ? v : hi;
                    }
                }
            }
        found[static_cast<std::size_t>(t)] = {lo, hi};
    });
    if (control.stopped()) throw Error(Status::cancelled, "value range cancelled");
    T lo = kHigh, hi = kLow;
    for (const auto& [l, h] : found) {
        lo = std::min(lo, l);
        hi = std::max(hi, h);
    }
    if constexpr (kFloat) {
        if (lo > hi) return {std::nan(""), std::nan("")}; // every sample NaN
    }
    return {static_cast<double>(lo), static_cast<double>(hi)};
}

} // namespace

Samples samples_of(const py::array& array, const char* what)
{
    if (array.ndim() != 3) {
        throw Error(Status::invalid_argument, std::string(what) + " has " + std::to_string(array.ndim()) +
                                                  " dimensions; expected a 3D array");
    }
    const py::dtype dtype = array.dtype();
    const std::optional<ScalarType> type = scalar_type(dtype.kind(), dtype.itemsize());
    if (!type) {
        throw Error(Status::invalid_argument, std::string(what) + " has samples of type " + dtype_text(array) +
                                                  "; expected int8, uint8, int16, uint16, int32, uint32, float32 or "
                                                  "float64 (or bool)");
    }
    if (!native_order(dtype.byteorder())) {
        throw Error(Status::invalid_argument, std::string(what) + " has samples of type " + dtype_text(array) +
                                                  " in the other byte order; expected the machine's");
    }
    const auto size = static_cast<std::int64_t>(dtype.itemsize());
    const auto address = reinterpret_cast<std::uintptr_t>(array.data());
    Samples s;
    s.array = array;
    s.type = *type;
    s.data = array.data();
    for (std::size_t a = 0; a < 3; ++a) {
        const auto axis = static_cast<py::ssize_t>(2 - a); // x is the last axis
        const auto bytes = static_cast<std::int64_t>(array.strides(axis));
        if (bytes % size != 0 || address % static_cast<std::uintptr_t>(size) != 0) {
            throw Error(Status::invalid_argument, std::string(what) + " is not aligned to its " + std::to_string(size) +
                                                      "-byte samples (stride " + std::to_string(bytes) +
                                                      " bytes); expected whole samples");
        }
        s.dims[a] = static_cast<std::int64_t>(array.shape(axis));
        s.strides[a] = bytes / size;
    }
    return s;
}

std::pair<double, double> value_range(const Samples& samples, int threads)
{
    if (samples.count() == 0) {
        throw Error(Status::invalid_argument, "the volume has no samples; expected at least one");
    }
    return run_interruptible<std::pair<double, double>>(
        samples.count() >= kBackgroundSamples, py::none(), [&](Control& control) {
            return dispatch_scalar_type(samples.type,
                                        [&](auto tag) { return range_of<decltype(tag)>(samples, threads, control); });
        });
}

} // namespace cmc33::python
