// io::read_mesh / io::write_mesh: choose the format by extension, map the input file, validate the
// mesh before writing. Also the text/number/output helpers of mesh_formats.hpp.

#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <variant>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#if defined(CMC33_WITH_LIBDEFLATE) && CMC33_WITH_LIBDEFLATE
#include <libdeflate.h>
#elif !defined(CMC33_WITH_ZLIB) || CMC33_WITH_ZLIB
#include <zlib.h>
#endif

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "atomic_file.hpp"
#include "mesh_formats.hpp"
#include "portability.hpp"

namespace cmc33::io {
namespace detail {

// ---- messages -------------------------------------------------------------------------------

std::string quote_text(std::string_view text, std::size_t max_chars)
{
    static constexpr char kHex[] = "0123456789abcdef";
    std::string s = "\"";
    for (std::size_t i = 0; i < text.size() && i < max_chars; ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') {
            s += static_cast<char>(c);
        } else {
            s += "\\x";
            s += kHex[c >> 4];
            s += kHex[c & 15];
        }
    }
    if (text.size() > max_chars) s += "...";
    s += '"';
    return s;
}

// ---- numbers --------------------------------------------------------------------------------

namespace {

std::string_view without_plus(std::string_view token)
{
    // from_chars rejects a leading '+'; "+-1" must stay invalid.
    if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') {
        token.remove_prefix(1);
    }
    return token;
}

} // namespace

bool parse_double(std::string_view token, double& value)
{
    token = without_plus(token);
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, value);
    if (ptr != end || token.empty()) return false;
    if (ec == std::errc::result_out_of_range) {
        // from_chars leaves value unchanged here; strtod gives the IEEE result (inf or
        // 0/subnormal).
        const std::string copy(token);
        value = std::strtod(copy.c_str(), nullptr);
        return true;
    }
    return ec == std::errc();
}

bool parse_float(std::string_view token, float& value)
{
    token = without_plus(token);
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, value);
    if (ptr != end || token.empty()) return false;
    if (ec == std::errc::result_out_of_range) {
        const std::string copy(token);
        value = std::strtof(copy.c_str(), nullptr);
        return true;
    }
    return ec == std::errc();
}

bool parse_int(std::string_view token, std::int64_t& value)
{
    token = without_plus(token);
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, value);
    return ec == std::errc() && ptr == end && !token.empty();
}

// ---- text -----------------------------------------------------------------------------------

namespace {

bool is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

} // namespace

void TextCursor::skip_blanks()
{
    while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
    if (comment_ != 0 && pos_ < text_.size() && text_[pos_] == comment_) {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    }
}

bool TextCursor::next_token_in_line(std::string_view& token)
{
    skip_blanks();
    if (pos_ >= text_.size() || text_[pos_] == '\n') return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_blank(text_[pos_]) && text_[pos_] != '\n') ++pos_;
    token = text_.substr(start, pos_ - start);
    return true;
}

bool TextCursor::next_token(std::string_view& token)
{
    for (;;) {
        if (next_token_in_line(token)) return true;
        if (pos_ >= text_.size()) return false;
        ++pos_; // the '\n'
        ++line_;
    }
}

void TextCursor::skip_line()
{
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    if (pos_ < text_.size()) {
        ++pos_;
        ++line_;
    }
}

std::string_view TextCursor::rest_of_line() const
{
    std::size_t end = pos_;
    while (end < text_.size() && text_[end] != '\n') ++end;
    std::string_view rest = text_.substr(pos_, end - pos_);
    while (!rest.empty() && is_blank(rest.back())) rest.remove_suffix(1);
    while (!rest.empty() && is_blank(rest.front())) rest.remove_prefix(1);
    return rest;
}

void check_text_end(std::string_view bytes, char comment, const std::string& name)
{
    if (bytes.empty() || bytes.back() == '\n' || is_blank(bytes.back())) return;
    const std::size_t newline = bytes.rfind('\n');
    const std::size_t start = newline == std::string_view::npos ? 0 : newline + 1;
    const std::string_view line = bytes.substr(start);
    if (comment != 0 && line.find(comment) != std::string_view::npos) return;
    std::size_t begin = line.size();
    while (begin > 0 && !is_blank(line[begin - 1])) --begin;
    const std::string_view token = line.substr(begin);
    auto starts_number = [](char c) { return (c >= '0' && c <= '9') || c == '+' || c == '-' || c == '.'; };
    auto continues_number = [](char c) {
        return (c >= '0' && c <= '9') || c == '.' || c == '/' || c == 'e' || c == 'E' || c == '+' ||
               c == '-';
    };
    if (token.empty() || !starts_number(token.front()) || !continues_number(token.back())) return;
    std::size_t line_number = 1;
    for (char c : bytes.substr(0, start)) line_number += c == '\n' ? 1 : 0;
    throw Error(Status::truncated_file,
                concat(name, ": line ", line_number, ": the file ends inside the number ",
                       quote_text(token),
                       " (no line end after it): cut short? A complete file ends its last line"));
}

// ---- output ---------------------------------------------------------------------------------

void OutputBuffer::bytes(const void* data, std::size_t count)
{
    const auto* p = static_cast<const char*>(data);
    if (count >= kBlock) { // a large block goes to the stream as it is
        flush();
        out_.write(p, static_cast<std::streamsize>(count));
        return;
    }
    const std::size_t first = std::min(count, kBlock - used_);
    std::memcpy(data_.get() + used_, p, first);
    used_ += first;
    if (first < count) {
        flush();
        std::memcpy(data_.get(), p + first, count - first);
        used_ = count - first;
    }
}

void OutputBuffer::real(float value)
{
    constexpr std::size_t kMax = 32; // the shortest float text is at most 15 characters
    if (kBlock - used_ < kMax) flush();
    used_ = static_cast<std::size_t>(std::to_chars(data_.get() + used_, data_.get() + used_ + kMax, value).ptr -
                                     data_.get());
}

void OutputBuffer::real(double value)
{
    constexpr std::size_t kMax = 40; // the shortest double text is at most 24 characters
    if (kBlock - used_ < kMax) flush();
    used_ = static_cast<std::size_t>(std::to_chars(data_.get() + used_, data_.get() + used_ + kMax, value).ptr -
                                     data_.get());
}

void OutputBuffer::unsigned_integer(std::uint64_t value)
{
    constexpr std::size_t kMax = 24; // 2^64 has 20 digits
    if (kBlock - used_ < kMax) flush();
    used_ = static_cast<std::size_t>(std::to_chars(data_.get() + used_, data_.get() + used_ + kMax, value).ptr -
                                     data_.get());
}

void OutputBuffer::signed_integer(std::int64_t value)
{
    constexpr std::size_t kMax = 24; // -2^63 has a sign and 19 digits
    if (kBlock - used_ < kMax) flush();
    used_ = static_cast<std::size_t>(std::to_chars(data_.get() + used_, data_.get() + used_ + kMax, value).ptr -
                                     data_.get());
}

void OutputBuffer::flush()
{
    out_.write(data_.get(), static_cast<std::streamsize>(used_));
    used_ = 0;
}

void write_position(OutputBuffer& o, const float* p, const double* offset)
{
    for (std::size_t k = 0; k < 3; ++k) {
        if (k > 0) o.character(' ');
        if (offset) {
            o.real(offset[k] + static_cast<double>(p[k]));
        } else {
            o.real(p[k]);
        }
    }
}

// ---- compression and text encodings of the glTF, VTP and GIfTI writers ------------------------

std::string zlib_compress(const void* data, std::size_t size, int level)
{
#if defined(CMC33_WITH_LIBDEFLATE) && CMC33_WITH_LIBDEFLATE
    // libdeflate compresses a whole buffer several times faster than zlib at the same ratio.
    struct Deleter {
        void operator()(libdeflate_compressor* c) const noexcept { libdeflate_free_compressor(c); }
    };
    // One compressor per thread and level, kept: .vtp compresses many small blocks.
    thread_local std::unique_ptr<libdeflate_compressor, Deleter> compressor;
    thread_local int compressor_level = -1;
    if (!compressor || compressor_level != level) {
        compressor.reset(libdeflate_alloc_compressor(level));
        compressor_level = level;
    }
    if (!compressor) throw Error(Status::too_large, "cannot allocate a deflate compressor (out of memory)");
    std::string out(libdeflate_zlib_compress_bound(compressor.get(), size), '\0');
    const std::size_t used = libdeflate_zlib_compress(compressor.get(), data, size, out.data(), out.size());
    if (used == 0) throw Error(Status::too_large, concat("cannot compress ", size, " bytes (libdeflate)"));
    out.resize(used);
    return out;
#elif !defined(CMC33_WITH_ZLIB) || CMC33_WITH_ZLIB
    uLongf bound = compressBound(static_cast<uLong>(size));
    std::string out(static_cast<std::size_t>(bound), '\0');
    const int status = compress2(reinterpret_cast<Bytef*>(out.data()), &bound, static_cast<const Bytef*>(data),
                                 static_cast<uLong>(size), level);
    if (status != Z_OK) {
        throw Error(Status::too_large, concat("cannot compress ", size, " bytes (zlib status ", status, ")"));
    }
    out.resize(static_cast<std::size_t>(bound));
    return out;
#else
    (void)level;
    // RFC 1950: CMF 0x78 (deflate, 32 KiB window), FLG 0x01 (FCHECK: 0x7801 is a multiple of 31);
    // RFC 1951 stored blocks (BTYPE 00) of at most 65535 bytes; the Adler-32 of the data, big-endian.
    const auto* p = static_cast<const unsigned char*>(data);
    std::string out;
    out.reserve(size + 6 + 5 * (size / 65535 + 1));
    out += static_cast<char>(0x78);
    out += static_cast<char>(0x01);
    std::size_t done = 0;
    do {
        const std::size_t n = std::min<std::size_t>(size - done, 65535);
        out += static_cast<char>(done + n == size ? 1 : 0);
        out += static_cast<char>(n & 0xff);
        out += static_cast<char>(n >> 8);
        out += static_cast<char>(~n & 0xff);
        out += static_cast<char>((~n >> 8) & 0xff);
        out.append(reinterpret_cast<const char*>(p + done), n);
        done += n;
    } while (done < size);
    std::uint32_t a = 1, b = 0;
    for (std::size_t i = 0; i < size; ++i) {
        a = (a + p[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    const std::uint32_t adler = (b << 16) | a;
    for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((adler >> shift) & 0xff);
    return out;
#endif
}

void append_base64(std::string& out, const void* data, std::size_t size)
{
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const auto* p = static_cast<const unsigned char*>(data);
    const std::size_t start = out.size();
    out.resize(start + (size + 2) / 3 * 4);
    char* o = out.data() + start;
    std::size_t i = 0;
    for (; i + 3 <= size; i += 3, o += 4) {
        const std::uint32_t v = (std::uint32_t{p[i]} << 16) | (std::uint32_t{p[i + 1]} << 8) | p[i + 2];
        o[0] = kAlphabet[v >> 18];
        o[1] = kAlphabet[(v >> 12) & 63];
        o[2] = kAlphabet[(v >> 6) & 63];
        o[3] = kAlphabet[v & 63];
    }
    if (i < size) {
        const bool two = i + 1 < size;
        const std::uint32_t v = (std::uint32_t{p[i]} << 16) | (two ? std::uint32_t{p[i + 1]} << 8 : 0u);
        o[0] = kAlphabet[v >> 18];
        o[1] = kAlphabet[(v >> 12) & 63];
        o[2] = two ? kAlphabet[(v >> 6) & 63] : '=';
        o[3] = '=';
    }
}

std::string xml_escape(std::string_view text)
{
    std::string out;
    for (char c : text) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        case '\'': out += "&apos;"; break;
        default: out += c;
        }
    }
    return out;
}

std::string json_string(std::string_view text)
{
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out = "\"";
    for (char c : text) {
        const auto u = static_cast<unsigned char>(c);
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (u < 0x20) {
            out += "\\u00";
            out += kHex[u >> 4];
            out += kHex[u & 15];
        } else {
            out += c;
        }
    }
    out += '"';
    return out;
}

// ---- dispatch -------------------------------------------------------------------------------

namespace {

constexpr const char* kAcceptedExtensions = ".ply, .obj, .stl or .off";
/// What write_mesh() accepts: the readers' formats and the formats written only.
constexpr const char* kWritableExtensions = ".ply, .obj, .stl, .off, .glb, .gltf, .vtp or .gii";

[[noreturn]] void unsupported_extension(const std::string& name, const std::string& ext,
                                        const char* expected = kAcceptedExtensions)
{
    throw Error(Status::unsupported_format, concat(name, ": unsupported mesh extension ",
                                                   ext.empty() ? "(none)" : quote_text(ext),
                                                   "; expected ", expected));
}

bool written_only(const std::string& ext)
{
    return ext == ".glb" || ext == ".gltf" || ext == ".vtp" || ext == ".gii";
}

std::optional<MeshFormat> mesh_format(const std::string& ext)
{
    if (ext == ".ply") return MeshFormat::ply;
    if (ext == ".obj") return MeshFormat::obj;
    if (ext == ".stl") return MeshFormat::stl;
    if (ext == ".off") return MeshFormat::off;
    return std::nullopt;
}

} // namespace

} // namespace detail

namespace {

// Closes a descriptor on every path out of FileImage's constructor.
struct Descriptor {
    int fd = -1;
    ~Descriptor()
    {
        if (fd >= 0) ::close(fd);
    }
};

// A read-only view of a whole file: memory-mapped (no copy; pages are read on demand), or read
// into memory where mapping is refused. A mapped file cut short by another process while being
// read would raise SIGBUS; our own writers never do that, they replace files by renaming.
class FileImage {
public:
    explicit FileImage(const std::filesystem::path& path)
    {
        const std::string name = path.string();
        Descriptor file{::open(name.c_str(), O_RDONLY | O_CLOEXEC)};
        if (file.fd < 0) {
            const int err = errno;
            throw Error(Status::io_error,
                        detail::concat(name, ": cannot open: ", std::strerror(err)));
        }
        struct stat info {};
        if (::fstat(file.fd, &info) != 0) {
            const int err = errno;
            throw Error(Status::io_error,
                        detail::concat(name, ": cannot stat: ", std::strerror(err)));
        }
        if (S_ISDIR(info.st_mode)) {
            throw Error(Status::io_error, name + ": is a directory; expected a mesh file");
        }
        if (!S_ISREG(info.st_mode)) {
            throw Error(Status::io_error, name + ": is not a regular file; expected a mesh file");
        }
        size_ = static_cast<std::size_t>(info.st_size);
        if (size_ == 0) return;
        if (const void* map = cmc33::detail::map_readonly(file.fd, size_)) {
            map_ = map;
            data_ = static_cast<const char*>(map);
            return;
        }
        copy_.resize(size_);
        std::size_t done = 0;
        while (done < size_) {
            const ::ssize_t got = ::read(file.fd, copy_.data() + done, size_ - done);
            if (got < 0 && errno == EINTR) continue;
            if (got < 0) {
                const int err = errno;
                throw Error(Status::io_error, detail::concat(name, ": read failed after ", done,
                                                             " bytes: ", std::strerror(err)));
            }
            if (got == 0) {
                throw Error(Status::io_error, detail::concat(name, ": the file shrank to ", done,
                                                             " bytes while being read"));
            }
            done += static_cast<std::size_t>(got);
        }
        data_ = copy_.data();
    }
    ~FileImage()
    {
        cmc33::detail::unmap(map_, size_);
    }
    FileImage(const FileImage&) = delete;
    FileImage& operator=(const FileImage&) = delete;

    std::string_view bytes() const noexcept { return {data_, size_}; }

private:
    const void* map_ = nullptr;
    const char* data_ = nullptr;
    std::size_t size_ = 0;
    std::string copy_;
};

void validate_for_writing(const Mesh& mesh, const std::string& name)
{
    auto fail = [&](const std::string& what) {
        throw Error(Status::invalid_argument, name + ": cannot write the mesh: " + what);
    };
    if (mesh.positions.size() % 3 != 0) {
        fail(detail::concat("positions hold ", mesh.positions.size(),
                            " floats; expected a multiple of 3"));
    }
    if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size()) {
        fail(detail::concat("normals hold ", mesh.normals.size(), " floats; expected 0 or ",
                            mesh.positions.size(), " (3 per vertex)"));
    }
    if (mesh.triangles.size() % 3 != 0) {
        fail(detail::concat("triangles hold ", mesh.triangles.size(),
                            " indices; expected a multiple of 3"));
    }
    if (mesh.vertex_count() > std::numeric_limits<std::uint32_t>::max()) {
        throw Error(Status::too_large, detail::concat(name, ": cannot write ", mesh.vertex_count(),
                                                      " vertices; at most 4294967295"));
    }
    const std::size_t n = mesh.vertex_count();
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        if (mesh.triangles[i] >= n) {
            fail(detail::concat("triangle ", i / 3, " uses vertex ", mesh.triangles[i],
                                " but the mesh has ", n, " vertices"));
        }
    }
}

void validate_arrays(const Mesh& mesh, const MeshWriteOptions& options, const std::string& name)
{
    auto check = [&](const std::vector<MeshArray>& arrays, std::size_t count, const char* per, const char* pers) {
        for (const MeshArray& a : arrays) {
            const std::size_t size = std::visit([](const auto& v) { return v.size(); }, a.values);
            if (a.name.empty() || a.components < 1 ||
                size != count * static_cast<std::size_t>(a.components)) {
                throw Error(Status::invalid_argument,
                            detail::concat(name, ": cannot write the array ", detail::quote_text(a.name), ": ", size,
                                           " values of ", a.components, " components; expected a name and ",
                                           a.components > 0 ? a.components : 1, " values per ", per, " (", count,
                                           " ", pers, ")"));
            }
        }
    };
    check(options.vertex_arrays, mesh.vertex_count(), "vertex", "vertices");
    check(options.triangle_arrays, mesh.triangle_count(), "triangle", "triangles");
}

/// A glTF scene of `parts` to path (.glb, or .gltf with its buffer in STEM.bin).
void write_gltf(const std::filesystem::path& path, const std::vector<detail::GltfPart>& parts,
                const MeshWriteOptions& options)
{
    if (detail::lower_extension(path) == ".gltf") {
        // The buffer goes to STEM.bin beside the JSON (a relative uri), written first: a .gltf on
        // disk always finds its whole buffer.
        std::filesystem::path bin = path;
        bin.replace_extension(".bin");
        detail::write_atomically(bin, [&](std::ostream& out) {
            detail::write_gltf_bin(parts, out);
            if (options.before_commit) options.before_commit();
        });
        detail::write_atomically(path, [&](std::ostream& out) {
            detail::write_gltf_json(parts, out, options, bin.filename().string());
        });
        return;
    }
    detail::write_atomically(path, [&](std::ostream& out) {
        detail::write_glb(parts, out, options, path.string());
        if (options.before_commit) options.before_commit();
    });
}

} // namespace

void write_scene(const std::vector<ScenePart>& parts, const std::filesystem::path& path, const MeshWriteOptions& options)
{
    const std::string name = path.string();
    const std::string ext = detail::lower_extension(path);
    if (ext != ".glb" && ext != ".gltf") {
        throw Error(Status::unsupported_format,
                    detail::concat(name, ": a scene of several meshes is written as glTF; expected .glb or .gltf"));
    }
    std::vector<detail::GltfPart> gltf;
    for (const ScenePart& part : parts) {
        if (!part.mesh) throw Error(Status::invalid_argument, detail::concat(name, ": a part of the scene has no mesh"));
        if (part.colour) {
            for (const float c : *part.colour)
                if (!(c >= 0 && c <= 1)) {
                    throw Error(Status::invalid_argument,
                                detail::concat(name, ": part \"", part.name, "\" has a colour component ",
                                               static_cast<double>(c), "; expected linear RGBA values in [0, 1]"));
                }
        }
        validate_for_writing(*part.mesh, name);
        gltf.push_back({part.mesh, part.name, part.colour});
    }
    write_gltf(path, gltf, options);
}

void write_mesh(const Mesh& mesh, const std::filesystem::path& path,
                const MeshWriteOptions& options)
{
    const std::string name = path.string();
    const std::string ext = detail::lower_extension(path);
    if (!detail::mesh_format(ext) && !detail::written_only(ext)) {
        detail::unsupported_extension(name, ext, detail::kWritableExtensions);
    }
    validate_for_writing(mesh, name);
    validate_arrays(mesh, options, name);
    const double* offset = options.offset ? options.offset->data() : nullptr;
    if (offset && ext == ".stl") {
        throw Error(Status::invalid_argument,
                    detail::concat(name, ": STL stores 32-bit float positions; this mesh's world coordinates need double "
                                         "precision (write .ply, .obj or .off)"));
    }
    if (ext == ".stl" && mesh.triangle_count() > std::numeric_limits<std::uint32_t>::max()) {
        throw Error(Status::too_large, detail::concat(name,
                                                      ": binary STL holds at most 4294967295 "
                                                      "triangles, not ",
                                                      mesh.triangle_count()));
    }
    if (ext == ".gltf" || ext == ".glb") return write_gltf(path, {{&mesh, {}, {}}}, options);
    // checked (names, a PLY type for every value) before the file is opened
    const std::vector<detail::PlyFaceArray> ply_faces =
        ext == ".ply" ? detail::ply_face_arrays(options.triangle_arrays, name) : std::vector<detail::PlyFaceArray>{};
    detail::write_atomically(path, [&](std::ostream& out) {
        if (ext == ".vtp") {
            detail::write_vtp(mesh, out, options, name);
        } else if (ext == ".gii") {
            detail::write_gifti(mesh, out, options, name);
        } else if (ext == ".ply") {
            detail::write_ply(mesh, out, options.ascii, offset, ply_faces);
        } else if (ext == ".obj") {
            detail::write_obj(mesh, out, offset);
        } else if (ext == ".stl") {
            detail::write_stl(mesh, out);
        } else {
            detail::write_off(mesh, out, offset);
        }
        if (options.before_commit) options.before_commit();
    });
}

Mesh read_mesh_from_memory(std::string_view bytes, MeshFormat format, const std::string& label)
{
    if (bytes.empty()) {
        static constexpr const char* kExpected[] = {"a PLY", "an OBJ", "an STL", "an OFF"};
        throw Error(Status::truncated_file,
                    detail::concat(label, ": the file is empty; expected ",
                                   kExpected[static_cast<int>(format)], " mesh"));
    }
    switch (format) {
    case MeshFormat::ply: return detail::read_ply(bytes, label);
    case MeshFormat::obj: return detail::read_obj(bytes, label);
    case MeshFormat::stl: return detail::read_stl(bytes, label);
    case MeshFormat::off: break;
    }
    return detail::read_off(bytes, label);
}

Mesh read_mesh(const std::filesystem::path& path)
{
    const std::string name = path.string();
    const std::string ext = detail::lower_extension(path);
    const std::optional<MeshFormat> format = detail::mesh_format(ext);
    if (!format && detail::written_only(ext)) {
        throw Error(Status::unsupported_format,
                    detail::concat(name, ": cmc33 writes ", detail::quote_text(ext),
                                   " meshes but does not read them; expected ", detail::kAcceptedExtensions));
    }
    if (!format) detail::unsupported_extension(name, ext);
    const FileImage file(path);
    return read_mesh_from_memory(file.bytes(), *format, name);
}

} // namespace cmc33::io
