#pragma once
// Internal: the mesh formats behind io::read_mesh / io::write_mesh (src/io/include/cmc33/io.hpp), and the
// small text and byte helpers they share (defined in mesh_io.cpp).
//
// Readers parse a whole file image held in memory (`bytes`, exactly the file's size) and name the
// file as `name` in their messages. They trust nothing in it: every count is checked against the
// bytes that remain before anything is allocated from it, and every read is bounds-checked.
// Writers stream a mesh that write_mesh() has already validated (sizes, indices < vertex count).

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/io_export.hpp"

namespace cmc33::io::detail {

Mesh read_ply(std::string_view bytes, const std::string& name);
Mesh read_obj(std::string_view bytes, const std::string& name);
Mesh read_stl(std::string_view bytes, const std::string& name);
Mesh read_off(std::string_view bytes, const std::string& name);

/// A triangle array (MeshWriteOptions::triangle_arrays) as PLY face properties after
/// vertex_indices: one scalar property per component, named as the array (NAME_0, NAME_1, ... when
/// it has several components), all of one 4-byte PLY type that holds every value exactly.
struct PlyFaceArray {
    const MeshArray* array = nullptr;
    const char* type = "float"; ///< "float", "int" or "uint"
};
/// The face properties of `arrays`, checked before anything is written: a Float32 array is float,
/// an Int32 array int, an Int64 array int when every value fits int32, uint when none is negative
/// and every value fits uint32, else refused (PLY has no 64-bit integers). Property names must be
/// PLY words (printable ASCII, no blank), distinct, and not vertex_indices / vertex_index.
/// @throws Error{invalid_argument} naming the file `name` and the array.
std::vector<PlyFaceArray> ply_face_arrays(const std::vector<MeshArray>& arrays, const std::string& name);

// `offset` (3 doubles) or null: positions are written in double precision as offset + position
// (a mesh extracted with its origin at 0, where 32-bit floats cannot keep it embedded in world space).
// `faces`: from ply_face_arrays(), one value per triangle and component each.
void write_ply(const Mesh& mesh, std::ostream& out, bool ascii, const double* offset = nullptr,
               const std::vector<PlyFaceArray>& faces = {});
/// The header write_ply writes for a mesh of these sizes. A binary file without face arrays
/// continues with kPlyVertexBytes (kPlyNormalVertexBytes with normals) per vertex, then
/// kPlyFaceBytes per triangle, so a writer that knows the sizes can place any slice of the mesh
/// (out-of-core slabs, MPI ranks: src/slabs) at its offset.
CMC33_IO_EXPORT std::string ply_header(std::uint64_t vertices, std::uint64_t triangles, bool normals, bool ascii,
                                       bool double_positions = false, const std::vector<PlyFaceArray>& faces = {});
inline constexpr std::size_t kPlyVertexBytes = 12;       ///< float x y z
inline constexpr std::size_t kPlyNormalVertexBytes = 24; ///< float x y z nx ny nz
inline constexpr std::size_t kPlyFaceBytes = 13;         ///< uchar 3, uint a b c
void write_obj(const Mesh& mesh, std::ostream& out, const double* offset = nullptr);
void write_stl(const Mesh& mesh, std::ostream& out);
void write_off(const Mesh& mesh, std::ostream& out, const double* offset = nullptr);

// ---- glTF 2.0, VTK XML PolyData, GIfTI (written only; mesh_gltf.cpp, mesh_vtp.cpp, mesh_gifti.cpp) ----

/// One mesh of a glTF scene: its own node and mesh, with a name and a base colour (linear RGBA)
/// when given. One part now; the per-label meshes of a label map are one part each.
struct GltfPart {
    const Mesh* mesh = nullptr;
    std::string name;                            ///< empty: none
    std::optional<std::array<float, 4>> colour{}; ///< a material's baseColorFactor
};
/// A binary glTF (.glb): the JSON chunk, then one buffer in the BIN chunk.
/// @throws Error{too_large} when the file would pass the 32-bit length of the GLB header.
void write_glb(const std::vector<GltfPart>& parts, std::ostream& out, const MeshWriteOptions& options,
               const std::string& name);
/// The JSON of a .gltf whose buffer is the file `bin_uri` (relative to it; percent-encoded here).
void write_gltf_json(const std::vector<GltfPart>& parts, std::ostream& out, const MeshWriteOptions& options,
                     const std::string& bin_uri);
/// The .bin of write_gltf_json.
void write_gltf_bin(const std::vector<GltfPart>& parts, std::ostream& out);

/// VTK XML PolyData, appended raw data compressed by blocks (vtkZLibDataCompressor).
void write_vtp(const Mesh& mesh, std::ostream& out, const MeshWriteOptions& options, const std::string& name);
/// GIfTI: a NIFTI_INTENT_POINTSET and a NIFTI_INTENT_TRIANGLE array (and NIFTI_INTENT_VECTOR
/// normals), GZipBase64Binary. @throws Error{too_large} past 2^31 - 1 vertices (INT32 indices).
void write_gifti(const Mesh& mesh, std::ostream& out, const MeshWriteOptions& options, const std::string& name);

/// `size` bytes as one zlib stream (RFC 1950): deflated with libdeflate or zlib where the build has
/// them, else in stored (uncompressed) deflate blocks, which every inflater reads.
std::string zlib_compress(const void* data, std::size_t size, int level);
/// Base64 (RFC 4648, with padding) of `size` bytes, appended to `out`.
void append_base64(std::string& out, const void* data, std::size_t size);
/// `text` with &, <, >, " and ' as XML character references.
std::string xml_escape(std::string_view text);
/// `text` as a JSON string literal (quotes included; control characters as \u00XX).
std::string json_string(std::string_view text);


class OutputBuffer;
/// "x y z" of a position as text: shortest floats, or offset + p in shortest doubles.
void write_position(OutputBuffer& o, const float* p, const double* offset);

// ---- messages -------------------------------------------------------------------------------

/// Concatenates anything `ostream <<` accepts.
template <class... Parts> std::string concat(const Parts&... parts)
{
    std::ostringstream s;
    (s << ... << parts);
    return s.str();
}

/// `text` in double quotes, non-printable bytes as \xNN, cut after `max_chars` characters.
std::string quote_text(std::string_view text, std::size_t max_chars = 32);

// ---- numbers --------------------------------------------------------------------------------
// The whole token must be the number; a leading '+' is accepted. Floats accept "nan" and "inf".
// A decimal beyond float range becomes +-inf or a (sub)normal/zero, like strtof.

bool parse_float(std::string_view token, float& value);
bool parse_double(std::string_view token, double& value);
bool parse_int(std::string_view token, std::int64_t& value);

// ---- text -----------------------------------------------------------------------------------

/// Text meshes are lines of records, and every writer ends its lines: a file whose last line has
/// no line end and ends in what may be part of a number (a digit, '.', '/', 'e', '+', '-'; the
/// token starts like a number) may have been cut inside that number, so it is refused
/// (docs/formats.md). Text after a `comment` character on that line is not looked at.
/// @throws Error{truncated_file}.
void check_text_end(std::string_view bytes, char comment, const std::string& name);

/// Whitespace-separated tokens over a text, with line numbers. '\n' ends a line ("\r\n" too);
/// when `comment` is not 0, a token starting with it hides the rest of its line.
class TextCursor {
public:
    explicit TextCursor(std::string_view text, char comment = 0) : text_(text), comment_(comment) {}

    /// The next token, on this line or a later one. False at the end of the text.
    bool next_token(std::string_view& token);
    /// The next token on the current line. False at the end of the line (which is not consumed).
    bool next_token_in_line(std::string_view& token);
    /// Moves past the end of the current line.
    void skip_line();
    /// The rest of the current line, without the line end (not consumed).
    std::string_view rest_of_line() const;
    /// 1-based number of the line the cursor is on.
    std::size_t line() const noexcept { return line_; }
    /// Bytes not yet consumed.
    std::size_t remaining() const noexcept { return text_.size() - pos_; }

private:
    void skip_blanks();
    std::string_view text_;
    std::size_t pos_ = 0;
    std::size_t line_ = 1;
    char comment_;
};

// ---- output ---------------------------------------------------------------------------------

/// Stores `value` at `out` in little-endian byte order.
template <class U> inline void store_le(char* out, U value) noexcept
{
    static_assert(std::is_unsigned_v<U>);
    if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(out, &value, sizeof(U));
    } else {
        for (std::size_t i = 0; i < sizeof(U); ++i) out[i] = static_cast<char>((value >> (8 * i)) & 0xffu);
    }
}
inline void store_f32_le(char* out, float value) noexcept { store_le(out, std::bit_cast<std::uint32_t>(value)); }

/// `count` floats at `out` in little-endian order (a plain copy on a little-endian machine).
inline void store_f32s_le(char* out, const float* values, std::size_t count) noexcept
{
    if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(out, values, count * sizeof(float));
    } else {
        for (std::size_t i = 0; i < count; ++i) store_f32_le(out + 4 * i, values[i]);
    }
}

/// `count` 32-bit unsigned integers at `out` in little-endian order.
inline void store_u32s_le(char* out, const std::uint32_t* values, std::size_t count) noexcept
{
    if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(out, values, count * sizeof(std::uint32_t));
    } else {
        for (std::size_t i = 0; i < count; ++i) store_le(out + 4 * i, values[i]);
    }
}

/// Accumulates output in one block and hands it to the stream when full: the writers' values go
/// into memory by plain stores (no stream call, no growth check per byte).
class OutputBuffer {
public:
    explicit OutputBuffer(std::ostream& out) : out_(out), data_(new char[kBlock]) {}
    ~OutputBuffer() = default;
    OutputBuffer(const OutputBuffer&) = delete;
    OutputBuffer& operator=(const OutputBuffer&) = delete;

    void text(std::string_view s) { bytes(s.data(), s.size()); }
    void character(char c)
    {
        if (used_ == kBlock) flush();
        data_[used_++] = c;
    }
    /// `count` bytes as they are.
    void bytes(const void* data, std::size_t count);
    /// Shortest decimal that reads back as exactly `value` (std::to_chars).
    void real(float value);
    void real(double value); ///< shortest text that reads back as the same double
    /// Decimal text of an integer of any width and sign, as printf's %lld or %llu writes it.
    template <class T>
        requires(std::integral<T> && !std::same_as<T, bool>)
    void integer(T value)
    {
        if constexpr (std::is_signed_v<T>) {
            signed_integer(static_cast<std::int64_t>(value));
        } else {
            unsigned_integer(static_cast<std::uint64_t>(value));
        }
    }
    void u8(std::uint8_t value) { character(static_cast<char>(value)); }
    void u16_le(std::uint16_t value) { put_le(value); }
    void u32_le(std::uint32_t value) { put_le(value); }
    void f32_le(float value) { put_le(std::bit_cast<std::uint32_t>(value)); }
    void f64_le(double value) { put_le(std::bit_cast<std::uint64_t>(value)); }
    /// `count` records of `size` bytes: fill(out, first, n) writes records first .. first + n - 1
    /// to out, as many at a time as the block has room for. A record larger than the block is
    /// filled alone in memory of its own and written through (n = 1).
    template <class Fill> void records(std::size_t count, std::size_t size, Fill&& fill)
    {
        if (size > kBlock) return large_records(count, size, fill);
        if (size == 0) return; // nothing to write (and no division by zero below)
        for (std::size_t first = 0; first < count;) {
            if (kBlock - used_ < size) flush();
            const std::size_t n = std::min(count - first, (kBlock - used_) / size);
            fill(data_.get() + used_, first, n);
            used_ += n * size;
            first += n;
        }
    }
    /// Writes what is left; call once at the end.
    void flush();

private:
    static constexpr std::size_t kBlock = std::size_t{1} << 18;
    void unsigned_integer(std::uint64_t value);
    void signed_integer(std::int64_t value);
    template <class Fill> void large_records(std::size_t count, std::size_t size, Fill& fill)
    {
        const std::unique_ptr<char[]> record(new char[size]);
        for (std::size_t r = 0; r < count; ++r) {
            fill(record.get(), r, std::size_t{1});
            bytes(record.get(), size); // at least a block: straight to the stream
        }
    }
    template <class U> void put_le(U value)
    {
        if (kBlock - used_ < sizeof(U)) flush();
        store_le(data_.get() + used_, value);
        used_ += sizeof(U);
    }
    std::ostream& out_;
    std::unique_ptr<char[]> data_;
    std::size_t used_ = 0;
};

} // namespace cmc33::io::detail
