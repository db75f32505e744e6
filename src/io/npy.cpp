// NumPy .npy (numpy.org/doc/stable/reference/generated/numpy.lib.format.html), versions 1.0, 2.0
// and 3.0: "\x93NUMPY", the version, the header's length (2 bytes in 1.0, 4 in 2.0 and 3.0, little
// endian), a Python dict literal {'descr': ..., 'fortran_order': ..., 'shape': (...)}, then the
// samples. Written for cmc33 from that description.
//
// Axes: an array indexed volume[z, y, x], as numpy holds images (and as the Python package
// passes arrays), so that in C order x varies fastest: shape (nz, ny, nx). A Fortran-order file
// holds the same array with z fastest; it is transposed on reading. A 4-D array is a stack
// volume[t, z, y, x] of which --frame N reads volume[N]. The frame is not in the file: spacing 1
// and origin 0, or ReadOptions::spacing/origin.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cmc33/io.hpp"
#include "byte_source.hpp"
#include "sample_conversion.hpp"
#include "volume_formats.hpp"

namespace cmc33::io::detail {
namespace {

constexpr std::string_view kMagic("\x93NUMPY", 6);

/// The header dict, as far as cmc33 reads it.
struct NpyHeader {
    std::string descr;
    bool fortran = false;
    std::vector<std::int64_t> shape;
};

/// A cursor over the dict literal; every failure names what was expected.
class DictParser {
public:
    DictParser(std::string_view text, const std::string& label) : text_(text), label_(label) {}

    NpyHeader parse()
    {
        NpyHeader h;
        bool has_descr = false, has_fortran = false, has_shape = false;
        expect('{');
        while (true) {
            skip_blanks();
            if (peek() == '}') {
                ++pos_;
                break;
            }
            const std::string key = string_literal("a key");
            expect(':');
            skip_blanks();
            if (key == "descr") {
                if (peek() == '[') fail("'descr' is a list of fields (a structured dtype); cmc33 reads one number per element");
                h.descr = string_literal("the dtype string");
                has_descr = true;
            } else if (key == "fortran_order") {
                h.fortran = boolean();
                has_fortran = true;
            } else if (key == "shape") {
                h.shape = tuple();
                has_shape = true;
            } else {
                fail("unknown key " + quote_bytes(key) + "; expected 'descr', 'fortran_order' and 'shape'");
            }
            skip_blanks();
            if (peek() == ',') {
                ++pos_;
                continue;
            }
            expect('}');
            break;
        }
        if (!has_descr || !has_fortran || !has_shape) {
            fail(str_cat("the header dict lacks ", !has_descr ? "'descr'" : !has_fortran ? "'fortran_order'" : "'shape'"));
        }
        return h;
    }

private:
    [[noreturn]] void fail(const std::string& what) const
    {
        throw Error(Status::bad_format, str_cat(label_, ": .npy header ", quote_bytes(text_, 80), ": ", what));
    }
    char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
    void skip_blanks()
    {
        while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    }
    void expect(char c)
    {
        skip_blanks();
        if (peek() != c) fail(str_cat("expected '", c, "' at character ", pos_ + 1));
        ++pos_;
    }
    std::string string_literal(std::string_view what)
    {
        skip_blanks();
        const char quote = peek();
        if (quote != '\'' && quote != '"') fail(str_cat("expected ", what, " in quotes at character ", pos_ + 1));
        const std::size_t end = text_.find(quote, pos_ + 1);
        if (end == std::string_view::npos) fail(str_cat(what, " has no closing quote"));
        std::string value(text_.substr(pos_ + 1, end - pos_ - 1));
        pos_ = end + 1;
        return value;
    }
    bool boolean()
    {
        if (text_.substr(pos_, 4) == "True") return pos_ += 4, true;
        if (text_.substr(pos_, 5) == "False") return pos_ += 5, false;
        fail(str_cat("'fortran_order' is not True or False at character ", pos_ + 1));
    }
    std::vector<std::int64_t> tuple()
    {
        expect('(');
        std::vector<std::int64_t> values;
        while (true) {
            skip_blanks();
            if (peek() == ')') {
                ++pos_;
                return values;
            }
            const std::size_t start = pos_;
            while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_]))) ++pos_;
            std::int64_t n = 0;
            if (pos_ == start || !parse_integer(text_.substr(start, pos_ - start), n)) {
                fail(str_cat("'shape' holds ", quote_bytes(text_.substr(start, 12)), ", expected sizes >= 0"));
            }
            if (peek() == 'L') ++pos_; // Python 2's long integers
            values.push_back(n);
            if (values.size() > 32) fail("'shape' has more than 32 sizes");
            skip_blanks();
            if (peek() == ',') {
                ++pos_;
            } else if (peek() != ')') {
                fail(str_cat("expected ',' or ')' in 'shape' at character ", pos_ + 1));
            }
        }
    }

    std::string_view text_;
    const std::string& label_;
    std::size_t pos_ = 0;
};

struct NpyType {
    ScalarType read_as;
    StoredKind kind;
    Endian endian;
    std::string name;
};

/// The sample type a dtype string names ('<f4', '>i2', '|u1', '=f8' ...), or an Error naming it.
NpyType sample_type(const std::string& descr, const std::string& label)
{
    NpyType t{ScalarType::u8, StoredKind::as_is, Endian::little, descr};
    std::string_view d = descr;
    char order = '|';
    if (!d.empty() && std::string_view("<>|=").find(d.front()) != std::string_view::npos) {
        order = d.front();
        d.remove_prefix(1);
    }
    t.endian = order == '>' ? Endian::big : order == '<' ? Endian::little : native_endian();
    const auto refuse = [&](std::string_view what) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": dtype ", quote_bytes(descr), " (", what,
                            ") is not a real number; cmc33 reads int8 to int64, uint8 to uint64, float16, float32 "
                            "and float64 samples"));
    };
    if (d.empty()) refuse("empty");
    const char kind = d.front();
    std::int64_t width = 0;
    if (d.size() > 1 && !parse_integer(d.substr(1), width)) width = -1;
    struct Known {
        char kind;
        std::int64_t width;
        ScalarType type;
        StoredKind stored;
        const char* name;
    };
    static constexpr Known kKnown[] = {
        {'i', 1, ScalarType::i8, StoredKind::as_is, "int8"},       {'u', 1, ScalarType::u8, StoredKind::as_is, "uint8"},
        {'i', 2, ScalarType::i16, StoredKind::as_is, "int16"},     {'u', 2, ScalarType::u16, StoredKind::as_is, "uint16"},
        {'i', 4, ScalarType::i32, StoredKind::as_is, "int32"},     {'u', 4, ScalarType::u32, StoredKind::as_is, "uint32"},
        {'i', 8, ScalarType::f64, StoredKind::int64, "int64"},     {'u', 8, ScalarType::f64, StoredKind::uint64, "uint64"},
        {'f', 2, ScalarType::u16, StoredKind::float16, "float16"}, {'f', 4, ScalarType::f32, StoredKind::as_is, "float32"},
        {'f', 8, ScalarType::f64, StoredKind::as_is, "float64"},
    };
    for (const Known& k : kKnown) {
        if (k.kind == kind && k.width == width) {
            t.read_as = k.type;
            t.kind = k.stored;
            t.name = k.name;
            return t;
        }
    }
    const std::string_view what = kind == 'b' || kind == '?' ? "bool"
                                  : kind == 'c'               ? "complex"
                                  : kind == 'O'               ? "Python objects"
                                  : kind == 'U'               ? "unicode text"
                                  : kind == 'S' || kind == 'a' ? "bytes"
                                  : kind == 'V'               ? "void, raw records"
                                  : kind == 'M'               ? "datetime64"
                                  : kind == 'm'               ? "timedelta64"
                                  : kind == 'f'               ? (width > 8 ? "extended precision float" : "float of an unknown width")
                                  : kind == 'i' || kind == 'u' ? "integer of an unknown width"
                                                               : "";
    if (!what.empty()) refuse(what);
    throw Error(Status::bad_format, str_cat(label, ": dtype ", quote_bytes(descr), " is not a numpy dtype string"));
}

/// The samples of `in` (dims in memory order reversed: z fastest) rearranged with x fastest.
Volume transposed(const Volume& in, const Index3& dims)
{
    Volume out(in.type(), dims, in.spacing(), in.origin());
    const std::size_t w = type_size(in.type());
    const auto nx = static_cast<std::size_t>(dims[0]), ny = static_cast<std::size_t>(dims[1]),
               nz = static_cast<std::size_t>(dims[2]);
    const std::byte* src = in.bytes();
    std::byte* dst = out.bytes();
    // source: element [z, y, x] at z + nz * (y + ny * x)
    for (std::size_t z = 0; z < nz; ++z)
        for (std::size_t y = 0; y < ny; ++y)
            for (std::size_t x = 0; x < nx; ++x)
                std::memcpy(dst + w * (x + nx * (y + ny * z)), src + w * (z + nz * (y + ny * x)), w);
    return out;
}

} // namespace

Volume read_npy(const ByteInput& file, const ReadOptions& options, const ReadSamples& read, bool planes)
{
    const std::string& label = file.label();
    const std::string start = file.read_string(0, 12);
    if (start.empty()) throw Error(Status::truncated_file, label + ": the file is empty (0 bytes), expected a .npy header");
    if (start.rfind(kMagic, 0) != 0) {
        throw Error(Status::bad_format, str_cat(label, ": not a .npy file: it starts with ", quote_bytes(start.substr(0, 6)),
                                                ", expected \"\\x93NUMPY\""));
    }
    if (start.size() < 10) throw Error(Status::truncated_file, label + ": the .npy header is cut short");
    const int major = static_cast<unsigned char>(start[6]), minor = static_cast<unsigned char>(start[7]);
    if (major < 1 || major > 3 || minor != 0) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": .npy format version ", major, '.', minor, "; cmc33 reads versions 1.0, 2.0 and 3.0"));
    }
    std::uint64_t header_len = 0, prefix = 10;
    if (major == 1) {
        header_len = static_cast<unsigned char>(start[8]) | static_cast<unsigned>(static_cast<unsigned char>(start[9])) << 8;
    } else {
        if (start.size() < 12) throw Error(Status::truncated_file, label + ": the .npy header is cut short");
        for (int i = 3; i >= 0; --i) header_len = header_len << 8 | static_cast<unsigned char>(start[8 + static_cast<std::size_t>(i)]);
        prefix = 12;
    }
    if (header_len > kMaxHeaderBytes) {
        throw Error(Status::bad_format, str_cat(label, ": the .npy header claims ", header_len, " bytes; real ones are a few hundred"));
    }
    if (file.size() < prefix + header_len) {
        throw Error(Status::truncated_file, str_cat(label, ": the .npy header declares ", header_len, " bytes but the file ends after ",
                                                    file.size() - prefix));
    }
    const std::string text = file.read_string(prefix, header_len);
    const NpyHeader h = DictParser(text, label).parse();
    const NpyType type = sample_type(h.descr, label);

    // [z, y, x] or [t, z, y, x]
    const std::size_t rank = h.shape.size();
    if (rank != 3 && rank != 4) {
        std::string shape = "(";
        for (std::size_t i = 0; i < rank; ++i) shape += str_cat(i ? ", " : "", h.shape[i]);
        throw Error(Status::unsupported_format,
                    str_cat(label, ": shape ", shape, rank == 1 ? ",)" : ")", ": ", rank,
                            "-D; cmc33 reads 3-D arrays volume[z, y, x] (or 4-D stacks volume[t, z, y, x] with --frame)"));
    }
    const std::int64_t frames = rank == 4 ? h.shape[0] : 1;
    const std::size_t s = rank - 3;
    Grid grid;
    grid.type = type.read_as;
    grid.dims = {h.shape[s + 2], h.shape[s + 1], h.shape[s]};
    grid.spacing = options.spacing.value_or(Vec3{1, 1, 1});
    grid.origin = options.origin.value_or(Vec3{0, 0, 0});
    grid.frame_source = options.spacing || options.origin ? "given (--spacing/--origin)" : "none in .npy (spacing 1, origin 0)";
    for (double v : grid.spacing) {
        if (!(v > 0) || !std::isfinite(v)) {
            throw Error(Status::invalid_argument, str_cat(label, ": spacing ", format_real(v), " is not a finite number > 0"));
        }
    }
    if (frames < 1) {
        throw Error(Status::bad_format, str_cat(label, ": shape[0] = ", frames, ": a stack of no volumes"));
    }
    std::int64_t frame = 0;
    if (options.frame) {
        frame = *options.frame;
        if (frame < 0 || frame >= frames) {
            throw Error(Status::invalid_argument,
                        frames == 1 && rank == 3
                            ? str_cat(label, ": frame ", frame, " asked for, but the array is one 3-D volume (frame 0)")
                            : str_cat(label, ": frame ", frame, " asked for, but the stack holds ", frames, " volumes (shape[0]): 0 to ",
                                      frames - 1));
        }
    } else if (frames > 1) {
        throw Error(Status::invalid_argument, str_cat(label, ": a 4-D array of ", frames,
                                                      " volumes volume[t, z, y, x]; choose one with --frame N, 0 to ", frames - 1));
    }
    const std::uint64_t frame_bytes = payload_bytes(grid.dims, grid.type, label);
    if (static_cast<std::uint64_t>(frames) > std::numeric_limits<std::uint64_t>::max() / 2 / frame_bytes) {
        throw Error(Status::too_large, str_cat(label, ": ", frames, " volumes of ", frame_bytes, " bytes overflow 64 bits"));
    }
    const std::uint64_t offset = prefix + header_len;
    const std::uint64_t total = static_cast<std::uint64_t>(frames) * frame_bytes;
    if (file.size() - offset != total) {
        throw Error(file.size() - offset < total ? Status::truncated_file : Status::bad_format,
                    str_cat(label, ": the .npy header declares ", frames > 1 ? str_cat(frames, " x ") : "", dims_text(grid.dims), ' ',
                            type.name, " (", total, " bytes) but ", file.size() - offset, " bytes follow byte ", offset,
                            file.size() - offset < total ? " (file cut short?)" : " (data appended?)"));
    }
    if (planes && (h.fortran || type.kind != StoredKind::as_is)) {
        throw Error(Status::unsupported_format,
                    str_cat(label, ": ", h.fortran ? "a Fortran-order array (z fastest) must be transposed"
                                                   : str_cat(type.name, " samples must be converted"),
                            " after reading, which --memory-limit cannot do plane by plane; read it without --memory-limit"));
    }
    Storage storage;
    storage.encoding = Encoding::raw;
    storage.endian = type.endian;
    storage.check_trailing = false; // checked above for the whole stack
    if (!h.fortran) {
        storage.offset = offset + static_cast<std::uint64_t>(frame) * frame_bytes;
        Volume volume = read(file, grid, storage, label, nullptr);
        return planes ? Volume{} : widen_samples(std::move(volume), type.kind);
    }
    // Fortran order: the first index varies fastest, so a stack [t, z, y, x] interleaves its
    // volumes sample by sample; read the whole stack and pick the frame.
    Grid stored = grid;
    stored.dims = {grid.dims[2], grid.dims[1], grid.dims[0] * frames};
    storage.offset = offset;
    const Volume all = read(file, stored, storage, label, nullptr);
    Volume volume;
    if (frames == 1) {
        volume = transposed(all, grid.dims);
    } else {
        // element [t, z, y, x] at t + T * (z + nz * (y + ny * x))
        volume = Volume(grid.type, grid.dims, grid.spacing, grid.origin);
        const std::size_t w = type_size(grid.type);
        const auto T = static_cast<std::size_t>(frames), t = static_cast<std::size_t>(frame);
        const auto nx = static_cast<std::size_t>(grid.dims[0]), ny = static_cast<std::size_t>(grid.dims[1]),
                   nz = static_cast<std::size_t>(grid.dims[2]);
        for (std::size_t z = 0; z < nz; ++z)
            for (std::size_t y = 0; y < ny; ++y)
                for (std::size_t x = 0; x < nx; ++x)
                    std::memcpy(volume.bytes() + w * (x + nx * (y + ny * z)), all.bytes() + w * (t + T * (z + nz * (y + ny * x))), w);
    }
    volume.set_spacing(grid.spacing);
    volume.set_origin(grid.origin);
    volume.set_frame_source(grid.frame_source);
    return widen_samples(std::move(volume), type.kind);
}

} // namespace cmc33::io::detail
