#include "cmc33/volume.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <string>

#include "portability.hpp"

namespace cmc33 {

std::string_view type_name(ScalarType type) noexcept
{
    switch (type) {
    case ScalarType::i8: return "int8";
    case ScalarType::u8: return "uint8";
    case ScalarType::i16: return "int16";
    case ScalarType::u16: return "uint16";
    case ScalarType::i32: return "int32";
    case ScalarType::u32: return "uint32";
    case ScalarType::f32: return "float";
    case ScalarType::f64: break;
    }
    return "double";
}

std::size_t type_size(ScalarType type) noexcept
{
    return dispatch_scalar_type(type, [](auto tag) { return sizeof(tag); });
}

namespace {

/// Bytes of the samples; sizes come from files, so every product is checked.
std::size_t checked_byte_size(ScalarType type, const Index3& dims)
{
    std::uint64_t bytes = type_size(type);
    for (std::int64_t d : dims) {
        if (d < 1) {
            throw Error(Status::invalid_argument, "volume dimension " + std::to_string(d) + " is not positive");
        }
        if (bytes > std::numeric_limits<std::uint64_t>::max() / static_cast<std::uint64_t>(d)) {
            throw Error(Status::too_large, "volume size " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) +
                                               "x" + std::to_string(dims[2]) + " overflows 64 bits");
        }
        bytes *= static_cast<std::uint64_t>(d);
    }
    if (bytes > static_cast<std::uint64_t>(std::numeric_limits<std::ptrdiff_t>::max())) {
        throw Error(Status::too_large, "volume of " + std::to_string(bytes) + " bytes is larger than memory can address");
    }
    return static_cast<std::size_t>(bytes);
}

} // namespace

Volume::Volume(ScalarType type, Index3 dims, Vec3 spacing, Vec3 origin)
    : type_(type), dims_(dims), spacing_(spacing), origin_(origin)
{
    const std::size_t bytes = checked_byte_size(type, dims);
    try {
        data_.reset(new std::byte[bytes]);
    } catch (const std::bad_alloc&) {
        throw Error(Status::too_large, "cannot allocate " + std::to_string(bytes) + " bytes for a " +
                                           std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                                           std::to_string(dims[2]) + " " + std::string(type_name(type)) + " volume");
    }
    // huge pages before the zeros are written (the readers fill this buffer next; the extractor's
    // passes read it twice)
    detail::advise_huge_pages_within(data_.get(), bytes);
    std::memset(data_.get(), 0, bytes);
}

Volume::Volume(ScalarType type, Index3 dims, Vec3 spacing, Vec3 origin, std::unique_ptr<std::byte[]> samples)
    : type_(type), dims_(dims), spacing_(spacing), origin_(origin)
{
    checked_byte_size(type, dims);
    if (!samples) throw Error(Status::invalid_argument, "volume samples are missing (null buffer)");
    data_ = std::move(samples);
}

void Volume::check_type(ScalarType wanted) const
{
    if (wanted != type_) {
        throw Error(Status::invalid_argument, "volume holds " + std::string(type_name(type_)) + " samples, not " +
                                                  std::string(type_name(wanted)));
    }
}

NonFinite find_non_finite(const Volume& volume)
{
    return volume.visit([&](auto view) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(view.data)>>;
        NonFinite result;
        if constexpr (std::is_floating_point_v<T>) {
            const std::int64_t n = volume.sample_count();
            for (std::int64_t i = 0; i < n; ++i) {
                if (!std::isfinite(view.data[i])) {
                    if (result.count++ == 0) {
                        result.first = {i % view.nx(), (i / view.nx()) % view.ny(), i / (view.nx() * view.ny())};
                    }
                }
            }
        }
        return result;
    });
}

std::pair<double, double> value_range(const Volume& volume)
{
    return volume.visit([&](auto view) {
        double lo = std::numeric_limits<double>::infinity();
        double hi = -lo;
        const std::int64_t n = volume.sample_count();
        for (std::int64_t i = 0; i < n; ++i) {
            const double v = static_cast<double>(view.data[i]);
            if (std::isfinite(v)) {
                lo = v < lo ? v : lo;
                hi = v > hi ? v : hi;
            }
        }
        return std::pair<double, double>{lo, hi};
    });
}

} // namespace cmc33
