#pragma once
/// @file volume.hpp
/// Volumes: `Volume` owns typed samples; `GridView<T>` is the non-owning view the extractor and
/// the verifier read. Samples are stored x fastest, then y, then z (C order [z][y][x]), in the
/// machine's byte order.
///
/// The frame: world position of sample (i, j, k) = origin + D * (spacing (.) (i, j, k)), where
/// D (`direction`) is a 3x3 matrix whose column a is the world direction of +axis a (unit length;
/// flips, permutations and oblique frames alike) and spacing (> 0) the distance between samples
/// along each axis. M = D * diag(spacing) is the index-to-world matrix (frame_matrix()). D is the
/// identity by default, so the older form origin + spacing * (i, j, k) is the default frame.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "cmc33/error.hpp"
#include "cmc33/base_export.hpp"

namespace cmc33 {

enum class ScalarType { i8, u8, i16, u16, i32, u32, f32, f64 };

/// "int8", "uint8", "int16", "uint16", "int32", "uint32", "float", "double".
CMC33_BASE_EXPORT std::string_view type_name(ScalarType type) noexcept;
/// Size of one sample in bytes.
CMC33_BASE_EXPORT std::size_t type_size(ScalarType type) noexcept;

template <class T> constexpr ScalarType scalar_type_of();
template <> constexpr ScalarType scalar_type_of<std::int8_t>() { return ScalarType::i8; }
template <> constexpr ScalarType scalar_type_of<std::uint8_t>() { return ScalarType::u8; }
template <> constexpr ScalarType scalar_type_of<std::int16_t>() { return ScalarType::i16; }
template <> constexpr ScalarType scalar_type_of<std::uint16_t>() { return ScalarType::u16; }
template <> constexpr ScalarType scalar_type_of<std::int32_t>() { return ScalarType::i32; }
template <> constexpr ScalarType scalar_type_of<std::uint32_t>() { return ScalarType::u32; }
template <> constexpr ScalarType scalar_type_of<float>() { return ScalarType::f32; }
template <> constexpr ScalarType scalar_type_of<double>() { return ScalarType::f64; }

using Index3 = std::array<std::int64_t, 3>;
using Vec3 = std::array<double, 3>;
/// Row-major: m[r][c] is row r, column c.
using Mat3 = std::array<Vec3, 3>;

inline constexpr Mat3 kIdentity3{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

/// M = D * diag(spacing): column a of M is the world step from sample index a to a + 1.
inline Mat3 frame_matrix(const Vec3& spacing, const Mat3& direction) noexcept
{
    Mat3 m{};
    for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 3; ++c) m[r][c] = direction[r][c] * spacing[c];
    return m;
}
/// Determinant of a 3x3 matrix.
inline double determinant(const Mat3& m) noexcept
{
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}
/// (M^-1)^T, the cofactor matrix over the determinant: it maps index-space gradients to world
/// ones (normals). M must be invertible.
inline Mat3 inverse_transpose(const Mat3& m) noexcept
{
    const double det = determinant(m);
    Mat3 r{};
    for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j) {
            const std::size_t i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            r[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / det;
        }
    return r;
}
/// True when only the diagonal is non-zero (an axis-aligned frame, possibly with flips).
inline bool is_diagonal(const Mat3& m) noexcept
{
    return m[0][1] == 0 && m[0][2] == 0 && m[1][0] == 0 && m[1][2] == 0 && m[2][0] == 0 && m[2][1] == 0;
}

/// Non-owning view of samples of type T. Strides are in elements and may be anything, negative
/// included (a numpy view such as vol[:, ::2, 10:200], Fortran order, a sub-block of a larger
/// array): `data` points at sample (0, 0, 0). Unit x-stride is the fast case.
template <class T> struct GridView {
    const T* data = nullptr;
    Index3 dims{0, 0, 0};    ///< samples along x, y, z
    Index3 strides{1, 0, 0}; ///< element strides along x, y, z
    Vec3 spacing{1, 1, 1};
    Vec3 origin{0, 0, 0};
    Mat3 direction = kIdentity3; ///< column a: world direction of +axis a (see the file comment)

    /// A dense view: strides {1, nx, nx*ny}.
    static GridView dense(const T* data, Index3 dims, Vec3 spacing = {1, 1, 1}, Vec3 origin = {0, 0, 0},
                          const Mat3& direction = kIdentity3)
    {
        return GridView{data, dims, {1, dims[0], dims[0] * dims[1]}, spacing, origin, direction};
    }
    std::int64_t nx() const noexcept { return dims[0]; }
    std::int64_t ny() const noexcept { return dims[1]; }
    std::int64_t nz() const noexcept { return dims[2]; }
    std::int64_t offset(std::int64_t i, std::int64_t j, std::int64_t k) const noexcept
    {
        return i * strides[0] + j * strides[1] + k * strides[2];
    }
    T operator()(std::int64_t i, std::int64_t j, std::int64_t k) const noexcept { return data[offset(i, j, k)]; }
};

/// Owns the samples of a volume read from a file or made by the caller.
class CMC33_BASE_EXPORT Volume {
public:
    Volume() = default;
    /// Allocates zeroed samples. @throws Error{too_large} if the size overflows or an axis < 1.
    Volume(ScalarType type, Index3 dims, Vec3 spacing = {1, 1, 1}, Vec3 origin = {0, 0, 0});
    /// Takes over `samples`, which must hold exactly the type_size(type) * nx * ny * nz bytes
    /// described (the readers fill such a buffer while checking a file, before the volume
    /// exists). @throws Error as above, or Error{invalid_argument} for a null buffer.
    Volume(ScalarType type, Index3 dims, Vec3 spacing, Vec3 origin, std::unique_ptr<std::byte[]> samples);

    ScalarType type() const noexcept { return type_; }
    const Index3& dims() const noexcept { return dims_; }
    const Vec3& spacing() const noexcept { return spacing_; }
    const Vec3& origin() const noexcept { return origin_; }
    /// Column a: world direction of +axis a, unit length (identity unless the file gave a frame).
    const Mat3& direction() const noexcept { return direction_; }
    /// The named space of the world coordinates as the file gave it ("left-posterior-superior",
    /// MetaImage "RAI", ...); empty when the file named none. Recorded, not interpreted.
    const std::string& space() const noexcept { return space_; }
    void set_spacing(const Vec3& s) noexcept { spacing_ = s; }
    void set_origin(const Vec3& o) noexcept { origin_ = o; }
    void set_direction(const Mat3& d) noexcept { direction_ = d; }
    void set_space(std::string name) { space_ = std::move(name); }
    /// Where the reader took the frame from, for `info` ("sform (code 2: aligned)", "qform",
    /// "pixdim", "Direction", ...); empty when the format has a single way to give it.
    const std::string& frame_source() const noexcept { return frame_source_; }
    void set_frame_source(std::string source) { frame_source_ = std::move(source); }
    std::int64_t sample_count() const noexcept { return dims_[0] * dims_[1] * dims_[2]; }
    std::size_t byte_size() const noexcept { return static_cast<std::size_t>(sample_count()) * type_size(type_); }
    std::byte* bytes() noexcept { return data_.get(); }
    const std::byte* bytes() const noexcept { return data_.get(); }

    /// Typed access. @throws Error{invalid_argument} if T is not the stored type.
    template <class T> T* samples()
    {
        check_type(scalar_type_of<T>());
        return reinterpret_cast<T*>(data_.get());
    }
    template <class T> const T* samples() const
    {
        check_type(scalar_type_of<T>());
        return reinterpret_cast<const T*>(data_.get());
    }
    template <class T> GridView<T> view() const
    {
        return GridView<T>::dense(samples<T>(), dims_, spacing_, origin_, direction_);
    }

    /// Calls f(GridView<T>) with T the stored sample type; returns what f returns.
    template <class F> decltype(auto) visit(F&& f) const;

private:
    void check_type(ScalarType wanted) const;
    ScalarType type_ = ScalarType::u8;
    Index3 dims_{0, 0, 0};
    Vec3 spacing_{1, 1, 1};
    Vec3 origin_{0, 0, 0};
    Mat3 direction_ = kIdentity3;
    std::string space_;
    std::string frame_source_;
    std::unique_ptr<std::byte[]> data_;
};

/// Calls f with a default-constructed value of the C++ type of `type` (dispatch helper).
template <class F> decltype(auto) dispatch_scalar_type(ScalarType type, F&& f)
{
    switch (type) {
    case ScalarType::i8: return f(std::int8_t{});
    case ScalarType::u8: return f(std::uint8_t{});
    case ScalarType::i16: return f(std::int16_t{});
    case ScalarType::u16: return f(std::uint16_t{});
    case ScalarType::i32: return f(std::int32_t{});
    case ScalarType::u32: return f(std::uint32_t{});
    case ScalarType::f32: return f(float{});
    case ScalarType::f64: break;
    }
    return f(double{});
}

template <class F> decltype(auto) Volume::visit(F&& f) const
{
    return dispatch_scalar_type(type_, [&](auto tag) -> decltype(auto) {
        using T = decltype(tag);
        return f(view<T>());
    });
}

/// Count and first position (x, y, z) of NaN or infinite samples; count 0 for integer types.
struct NonFinite {
    std::int64_t count = 0;
    Index3 first{-1, -1, -1};
};
CMC33_BASE_EXPORT NonFinite find_non_finite(const Volume& volume);

/// Smallest and largest sample (non-finite samples skipped).
CMC33_BASE_EXPORT std::pair<double, double> value_range(const Volume& volume);

} // namespace cmc33
