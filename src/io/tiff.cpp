// TIFF volumes through libtiff (contract in tiff.hpp; what is read and refused: docs/formats.md).
//
// libtiff reads through the project's ByteInput (TIFFClientOpen with bounded reads), so a file and
// bytes in memory take the same path. Pages are decoded by libtiff (any compression it was built
// with, strips or tiles, BigTIFF) straight into the volume's planes.

#include "tiff.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "cmc33/error.hpp"
#include "atomic_file.hpp"
#include "byte_source.hpp"
#include "volume_formats.hpp"

#if CMC33_WITH_TIFF
#include <tiffio.h>
#endif

namespace cmc33::io::detail {

namespace fs = std::filesystem;

bool has_tiff_mark(std::string_view head) noexcept
{
    if (head.size() < 4) return false;
    const std::string_view m = head.substr(0, 4);
    return m == std::string_view("II*\0", 4) || m == std::string_view("MM\0*", 4) || m == std::string_view("II+\0", 4) ||
           m == std::string_view("MM\0+", 4);
}

namespace {

bool tiff_extension(const fs::path& path)
{
    const std::string ext = lower_extension(path);
    return ext == ".tif" || ext == ".tiff";
}

/// The .tif/.tiff files directly in a folder (hidden ones skipped).
std::vector<fs::path> folder_tiff_files(const fs::path& folder)
{
    std::vector<fs::path> files;
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.empty() || name[0] == '.') continue;
        if (tiff_extension(it->path()) && it->is_regular_file(ec)) files.push_back(it->path());
    }
    if (ec) throw Error(Status::io_error, str_cat(folder.string(), ": cannot list the folder: ", ec.message()));
    std::sort(files.begin(), files.end());
    return files;
}

} // namespace

bool looks_like_tiff(const fs::path& path)
{
    std::error_code ec;
    try {
        if (fs::is_directory(path, ec)) return !folder_tiff_files(path).empty();
        const InputFile file(path, path.string());
        return has_tiff_mark(file.read_string(0, 4));
    } catch (const Error&) {
        return false;
    }
}

#if !CMC33_WITH_TIFF

bool tiff_supported() noexcept { return false; }

namespace {
[[noreturn]] void no_tiff(const std::string& label)
{
    throw Error(Status::unsupported_format, label + ": TIFF input, but this build of cmc33 has no TIFF reader (built without "
                                                    "libtiff); convert the stack to NRRD, or use a build with libtiff");
}
} // namespace

Volume read_tiff(const fs::path& path, const ReadOptions&) { no_tiff(path.string()); }
Volume read_tiff_memory(std::string_view, const std::string& label, const ReadOptions&) { no_tiff(label); }
std::vector<fs::path> tiff_input_files(const fs::path& path) { return {path}; }

#else

bool tiff_supported() noexcept { return true; }

namespace {

// ---- libtiff over a ByteInput ---------------------------------------------------------------

struct Client {
    const ByteInput* input = nullptr;
    std::uint64_t position = 0;
    std::string first_error; // libtiff's first error message, for ours
};

tmsize_t client_read(thandle_t handle, void* out, tmsize_t count)
{
    auto* c = static_cast<Client*>(handle);
    if (count <= 0 || c->position >= c->input->size()) return 0;
    const std::uint64_t n = std::min<std::uint64_t>(static_cast<std::uint64_t>(count), c->input->size() - c->position);
    try {
        c->input->read(c->position, out, static_cast<std::size_t>(n));
    } catch (const Error&) {
        return -1;
    }
    c->position += n;
    return static_cast<tmsize_t>(n);
}

tmsize_t client_write(thandle_t, void*, tmsize_t) { return -1; }

toff_t client_seek(thandle_t handle, toff_t offset, int whence)
{
    auto* c = static_cast<Client*>(handle);
    std::uint64_t base = 0;
    if (whence == SEEK_CUR) base = c->position;
    else if (whence == SEEK_END) base = c->input->size();
    if (offset > std::numeric_limits<std::uint64_t>::max() - base) return static_cast<toff_t>(-1);
    c->position = base + offset;
    return c->position;
}

int client_close(thandle_t) { return 0; }
toff_t client_size(thandle_t handle) { return static_cast<Client*>(handle)->input->size(); }
int client_map(thandle_t, void**, toff_t*) { return 0; }
void client_unmap(thandle_t, void*, toff_t) {}

int on_error(TIFF*, void* user, const char* module, const char* format, va_list args)
{
    auto* c = static_cast<Client*>(user);
    if (c->first_error.empty()) {
        char buffer[512];
        std::vsnprintf(buffer, sizeof buffer, format, args);
        c->first_error = std::string(buffer);
        if (module && *module) c->first_error = std::string(module) + ": " + c->first_error;
        for (char& ch : c->first_error) {
            if (ch == '\n' || ch == '\r') ch = ' ';
        }
    }
    return 1; // handled: nothing on stderr
}

int on_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

/// An open TIFF, closed on scope exit.
class Tiff {
public:
    Tiff(const ByteInput& input) : client_{&input, 0, {}}
    {
        TIFFOpenOptions* options = TIFFOpenOptionsAlloc();
        TIFFOpenOptionsSetErrorHandlerExtR(options, on_error, &client_);
        TIFFOpenOptionsSetWarningHandlerExtR(options, on_warning, &client_);
        // no single allocation larger than the file could need (a lying header asks for more)
        TIFFOpenOptionsSetMaxSingleMemAlloc(options, static_cast<tmsize_t>(std::min<std::uint64_t>(
                                                         std::uint64_t{1} << 40, std::max<std::uint64_t>(input.size() * 2048, 1 << 24))));
        // "m": no memory mapping (reads go through the ByteInput); "h": headers only at open
        tif_ = TIFFClientOpenExt(input.label().c_str(), "rm", &client_, client_read, client_write, client_seek, client_close,
                                 client_size, client_map, client_unmap, options);
        TIFFOpenOptionsFree(options);
        if (!tif_) {
            throw Error(Status::bad_format, str_cat(input.label(), ": not a TIFF file libtiff can read (",
                                                    client_.first_error.empty() ? "no TIFF header" : client_.first_error, ")"));
        }
    }
    ~Tiff()
    {
        if (tif_) TIFFClose(tif_);
    }
    Tiff(const Tiff&) = delete;
    Tiff& operator=(const Tiff&) = delete;
    TIFF* get() const noexcept { return tif_; }
    /// libtiff's first error, or `fallback`.
    std::string why(std::string_view fallback) const
    {
        return client_.first_error.empty() ? std::string(fallback) : client_.first_error;
    }

private:
    Client client_;
    TIFF* tif_ = nullptr;
};

// ---- pages ----------------------------------------------------------------------------------

/// What a page (an image file directory) holds.
struct Page {
    std::uint32_t width = 0, height = 0;
    std::uint16_t bits = 0, format = SAMPLEFORMAT_UINT, samples = 1, photometric = PHOTOMETRIC_MINISBLACK;
    bool tiled = false;
    std::string description;
    std::optional<double> x_resolution, y_resolution;
    std::uint16_t resolution_unit = RESUNIT_INCH;
};

Page read_page(TIFF* tif)
{
    Page p;
    TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &p.width);
    TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &p.height);
    TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &p.bits);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &p.format);
    TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &p.samples);
    if (!TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &p.photometric)) p.photometric = PHOTOMETRIC_MINISBLACK;
    p.tiled = TIFFIsTiled(tif) != 0;
    char* description = nullptr;
    if (TIFFGetField(tif, TIFFTAG_IMAGEDESCRIPTION, &description) && description) p.description = description;
    float r = 0;
    if (TIFFGetField(tif, TIFFTAG_XRESOLUTION, &r) && std::isfinite(r) && r > 0) p.x_resolution = static_cast<double>(r);
    if (TIFFGetField(tif, TIFFTAG_YRESOLUTION, &r) && std::isfinite(r) && r > 0) p.y_resolution = static_cast<double>(r);
    TIFFGetFieldDefaulted(tif, TIFFTAG_RESOLUTIONUNIT, &p.resolution_unit);
    return p;
}

bool is_reduced(TIFF* tif)
{
    std::uint32_t type = 0;
    return TIFFGetField(tif, TIFFTAG_SUBFILETYPE, &type) && (type & FILETYPE_REDUCEDIMAGE);
}

/// The sample type of a page, or Error naming what it holds instead.
ScalarType page_type(const Page& p, const std::string& label)
{
    if (p.samples != 1) {
        const std::string what = p.photometric == PHOTOMETRIC_RGB         ? "RGB"
                                 : p.photometric == PHOTOMETRIC_YCBCR     ? "YCbCr"
                                 : p.photometric == PHOTOMETRIC_SEPARATED ? "CMYK"
                                                                          : "multi-channel";
        throw Error(Status::unsupported_format, str_cat(label, ": ", p.samples, " samples per pixel (", what,
                                                        "); expected one sample per pixel, a grey-level stack"));
    }
    if (p.photometric == PHOTOMETRIC_PALETTE) {
        throw Error(Status::unsupported_format, label + ": a palette-color image; expected grey levels (one sample per pixel)");
    }
    if (p.format == SAMPLEFORMAT_IEEEFP) {
        if (p.bits == 32) return ScalarType::f32;
        if (p.bits == 64) return ScalarType::f64;
    } else if (p.format == SAMPLEFORMAT_INT) {
        if (p.bits == 8) return ScalarType::i8;
        if (p.bits == 16) return ScalarType::i16;
        if (p.bits == 32) return ScalarType::i32;
    } else if (p.format == SAMPLEFORMAT_UINT || p.format == SAMPLEFORMAT_VOID) {
        if (p.bits == 8) return ScalarType::u8;
        if (p.bits == 16) return ScalarType::u16;
        if (p.bits == 32) return ScalarType::u32;
    }
    const std::string format = p.format == SAMPLEFORMAT_IEEEFP    ? "floating-point"
                               : p.format == SAMPLEFORMAT_INT     ? "signed integer"
                               : p.format == SAMPLEFORMAT_UINT    ? "unsigned integer"
                               : p.format == SAMPLEFORMAT_COMPLEXINT || p.format == SAMPLEFORMAT_COMPLEXIEEEFP ? "complex"
                                                                                                              : "unknown-format";
    throw Error(Status::unsupported_format,
                str_cat(label, ": ", p.bits, "-bit ", format, " samples; expected 8, 16 or 32-bit integers or 32 or 64-bit floats"));
}

/// Decodes the current page into `out` (width * height samples of `type`, rows top to bottom).
void decode_page(const Tiff& tiff, const Page& p, ScalarType type, std::byte* out, const std::string& label)
{
    TIFF* tif = tiff.get();
    const std::size_t width = type_size(type);
    const std::size_t row_bytes = static_cast<std::size_t>(p.width) * width;
    if (!p.tiled) {
        std::uint32_t rows_per_strip = 0;
        TIFFGetFieldDefaulted(tif, TIFFTAG_ROWSPERSTRIP, &rows_per_strip);
        if (rows_per_strip == 0 || rows_per_strip > p.height) rows_per_strip = p.height;
        const std::uint32_t strips = TIFFNumberOfStrips(tif);
        const std::uint32_t needed = (p.height + rows_per_strip - 1) / rows_per_strip;
        if (strips < needed) {
            throw Error(Status::bad_format, str_cat(label, ": ", strips, " strips for ", p.height, " rows of ", rows_per_strip,
                                                    " per strip; expected ", needed));
        }
        std::vector<std::byte> spare;
        for (std::uint32_t s = 0; s < needed; ++s) {
            const std::uint32_t row = s * rows_per_strip;
            const std::uint32_t rows = std::min(rows_per_strip, p.height - row);
            const std::size_t bytes = rows * row_bytes;
            const tmsize_t got = TIFFReadEncodedStrip(tif, s, out + row * row_bytes, static_cast<tmsize_t>(bytes));
            if (got < 0 || static_cast<std::size_t>(got) < bytes) {
                throw Error(Status::bad_format, str_cat(label, ": strip ", s, " (rows ", row, " to ", row + rows - 1, ") ",
                                                        got < 0 ? "cannot be decoded: " + tiff.why("corrupt data")
                                                                : str_cat("holds ", got, " bytes, expected ", bytes)));
            }
        }
        return;
    }
    std::uint32_t tile_w = 0, tile_h = 0;
    TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tile_w);
    TIFFGetField(tif, TIFFTAG_TILELENGTH, &tile_h);
    if (tile_w == 0 || tile_h == 0 || tile_w > (1u << 16) || tile_h > (1u << 16)) {
        throw Error(Status::bad_format, str_cat(label, ": tiles of ", tile_w, "x", tile_h, " pixels; expected 1 to 65536 on each side"));
    }
    const std::size_t tile_bytes = static_cast<std::size_t>(tile_w) * tile_h * width;
    std::vector<std::byte> tile(tile_bytes);
    for (std::uint32_t y = 0; y < p.height; y += tile_h) {
        for (std::uint32_t x = 0; x < p.width; x += tile_w) {
            const std::uint32_t index = TIFFComputeTile(tif, x, y, 0, 0);
            const tmsize_t got = TIFFReadEncodedTile(tif, index, tile.data(), static_cast<tmsize_t>(tile_bytes));
            if (got < 0 || static_cast<std::size_t>(got) < tile_bytes) {
                throw Error(Status::bad_format, str_cat(label, ": the tile at x ", x, ", y ", y, " ",
                                                        got < 0 ? "cannot be decoded: " + tiff.why("corrupt data")
                                                                : str_cat("holds ", got, " bytes, expected ", tile_bytes)));
            }
            const std::uint32_t w = std::min(tile_w, p.width - x), h = std::min(tile_h, p.height - y);
            for (std::uint32_t r = 0; r < h; ++r) {
                std::memcpy(out + (static_cast<std::size_t>(y + r) * p.width + x) * width,
                            tile.data() + static_cast<std::size_t>(r) * tile_w * width, static_cast<std::size_t>(w) * width);
            }
        }
    }
}

// ---- descriptions ---------------------------------------------------------------------------

/// ImageJ's "key=value" lines (the description starts with "ImageJ=").
std::map<std::string, std::string> imagej_fields(const std::string& description)
{
    std::map<std::string, std::string> fields;
    if (description.rfind("ImageJ=", 0) != 0) return fields;
    std::size_t start = 0;
    while (start < description.size()) {
        std::size_t stop = description.find('\n', start);
        if (stop == std::string::npos) stop = description.size();
        const std::string_view line = trim(std::string_view(description).substr(start, stop - start));
        const std::size_t eq = line.find('=');
        if (eq != std::string_view::npos) fields[std::string(trim(line.substr(0, eq)))] = std::string(trim(line.substr(eq + 1)));
        start = stop + 1;
    }
    return fields;
}

/// An attribute of the first element `element` in OME-XML text (without a parser: the attributes
/// of Pixels are all it needs).
std::optional<std::string> xml_attribute(const std::string& xml, std::string_view element, std::string_view name)
{
    std::size_t at = 0;
    while ((at = xml.find(str_cat("<", element), at)) != std::string::npos) {
        const std::size_t after = at + 1 + element.size();
        if (after < xml.size() && (std::isspace(static_cast<unsigned char>(xml[after])) || xml[after] == '>' || xml[after] == '/')) break;
        at = after;
    }
    if (at == std::string::npos) return std::nullopt;
    const std::size_t end = xml.find('>', at);
    const std::string_view tag = std::string_view(xml).substr(at, end == std::string::npos ? std::string::npos : end - at);
    std::size_t pos = 0;
    while ((pos = tag.find(name, pos)) != std::string_view::npos) {
        const bool starts = pos > 0 && std::isspace(static_cast<unsigned char>(tag[pos - 1]));
        std::size_t q = pos + name.size();
        while (q < tag.size() && std::isspace(static_cast<unsigned char>(tag[q]))) ++q;
        if (starts && q < tag.size() && tag[q] == '=') {
            ++q;
            while (q < tag.size() && std::isspace(static_cast<unsigned char>(tag[q]))) ++q;
            if (q < tag.size() && (tag[q] == '"' || tag[q] == '\'')) {
                const char quote = tag[q];
                const std::size_t close = tag.find(quote, q + 1);
                if (close != std::string_view::npos) return std::string(tag.substr(q + 1, close - q - 1));
            }
            return std::nullopt;
        }
        pos += name.size();
    }
    return std::nullopt;
}

std::optional<double> positive_number(const std::optional<std::string>& text)
{
    double v = 0;
    if (text && parse_real(trim(*text), v) && std::isfinite(v) && v > 0) return v;
    return std::nullopt;
}

std::optional<std::int64_t> count_value(const std::optional<std::string>& text)
{
    std::int64_t v = 0;
    if (text && parse_integer(trim(*text), v) && v >= 1) return v;
    return std::nullopt;
}

/// How a multi-page file's pages map to the volume: which pages are its z slices, and its spacing.
struct Layout {
    std::vector<std::size_t> pages; // page index of each z slice
    Vec3 spacing{1, 1, 1};
};

std::optional<std::string> field(const std::map<std::string, std::string>& fields, const std::string& key)
{
    const auto it = fields.find(key);
    if (it == fields.end()) return std::nullopt;
    return it->second;
}

/// The frame to read among `frames`, or Error.
std::int64_t choose_frame(std::int64_t frames, const ReadOptions& options, const std::string& label, std::string_view what)
{
    if (frames > 1 && !options.frame) {
        throw Error(Status::bad_format, str_cat(label, ": ", what, " holds ", frames, " time frames; choose one with --frame N (0 to ",
                                                frames - 1, ")"));
    }
    const std::int64_t f = options.frame.value_or(0);
    if (f < 0 || f >= frames) {
        throw Error(Status::invalid_argument, str_cat(label, ": --frame ", f, " is out of range; ", what, " holds ", frames,
                                                      frames == 1 ? " frame (0)" : str_cat(" frames (0 to ", frames - 1, ")")));
    }
    return f;
}

Layout page_layout(const Page& first, std::size_t page_count, const ReadOptions& options, const std::string& label)
{
    Layout layout;
    const auto ij = imagej_fields(first.description);
    if (!ij.empty()) {
        const std::int64_t channels = count_value(field(ij, "channels")).value_or(1);
        const std::int64_t frames = count_value(field(ij, "frames")).value_or(1);
        const std::int64_t images = count_value(field(ij, "images")).value_or(static_cast<std::int64_t>(page_count));
        const std::int64_t slices = count_value(field(ij, "slices")).value_or(images / std::max<std::int64_t>(1, channels * frames));
        if (channels > 1) {
            throw Error(Status::unsupported_format, str_cat(label, ": an ImageJ hyperstack of ", channels,
                                                            " channels; expected one channel (split the channels in ImageJ first)"));
        }
        if (slices * frames != images || static_cast<std::int64_t>(page_count) != images) {
            throw Error(Status::bad_format, str_cat(label, ": ImageJ's description says images=", images, ", slices=", slices, ", frames=",
                                                    frames, " but the file has ", page_count, " page", page_count == 1 ? "" : "s",
                                                    "; expected images = slices x frames pages"));
        }
        const std::int64_t f = choose_frame(frames, options, label, "the ImageJ hyperstack");
        for (std::int64_t z = 0; z < slices; ++z) layout.pages.push_back(static_cast<std::size_t>(f * slices + z));
        // ImageJ: XResolution/YResolution are pixels per unit (unit=), spacing= is the z step
        if (first.x_resolution) layout.spacing[0] = 1 / *first.x_resolution;
        if (first.y_resolution) layout.spacing[1] = 1 / *first.y_resolution;
        if (auto z = positive_number(field(ij, "spacing"))) layout.spacing[2] = *z;
        return layout;
    }
    if (first.description.find("<OME") != std::string::npos) {
        const std::string& xml = first.description;
        const auto size = [&](std::string_view name) { return count_value(xml_attribute(xml, "Pixels", name)).value_or(1); };
        const std::int64_t nz = size("SizeZ"), nc = size("SizeC"), nt = size("SizeT");
        const std::string order = xml_attribute(xml, "Pixels", "DimensionOrder").value_or("XYZCT");
        if (nc > 1) {
            throw Error(Status::unsupported_format,
                        str_cat(label, ": OME-TIFF with SizeC=", nc, " channels; expected one channel, a grey-level stack"));
        }
        if (nz * nt != static_cast<std::int64_t>(page_count) || order.size() != 5 || order.rfind("XY", 0) != 0) {
            throw Error(Status::bad_format, str_cat(label, ": OME-XML says SizeZ=", nz, ", SizeT=", nt, ", DimensionOrder=", quote_bytes(order),
                                                    " but the file has ", page_count, " page", page_count == 1 ? "" : "s",
                                                    "; expected SizeZ x SizeT pages of one series"));
        }
        const std::int64_t t = choose_frame(nt, options, label, "the OME-TIFF");
        // the page of (z, t): the letter after XY that comes first varies fastest (C has size 1)
        const bool z_first = order.find('Z') < order.find('T');
        for (std::int64_t z = 0; z < nz; ++z) layout.pages.push_back(static_cast<std::size_t>(z_first ? t * nz + z : z * nt + t));
        if (auto v = positive_number(xml_attribute(xml, "Pixels", "PhysicalSizeX"))) layout.spacing[0] = *v;
        if (auto v = positive_number(xml_attribute(xml, "Pixels", "PhysicalSizeY"))) layout.spacing[1] = *v;
        if (auto v = positive_number(xml_attribute(xml, "Pixels", "PhysicalSizeZ"))) layout.spacing[2] = *v;
        return layout;
    }
    if (options.frame && *options.frame != 0) {
        throw Error(Status::invalid_argument,
                    str_cat(label, ": --frame ", *options.frame, " is out of range; a plain TIFF stack holds 1 frame (0)"));
    }
    for (std::size_t k = 0; k < page_count; ++k) layout.pages.push_back(k);
    return layout;
}

/// Reads the pages of one file: the slices `layout` picks.
Volume read_tiff_input(const ByteInput& input, const ReadOptions& options)
{
    const std::string& label = input.label();
    const Tiff tiff(input);
    TIFF* tif = tiff.get();
    // the full-resolution pages (reduced-resolution ones are thumbnails or pyramid levels)
    std::vector<tdir_t> pages;
    Page first;
    for (tdir_t d = 0;; ++d) {
        if (!is_reduced(tif)) {
            if (pages.empty()) first = read_page(tif);
            pages.push_back(d);
        }
        if (pages.size() > (std::size_t{1} << 20)) {
            throw Error(Status::too_large, label + ": more than 1048576 pages");
        }
        if (!TIFFReadDirectory(tif)) break;
    }
    if (!tiff.why("").empty() && pages.empty()) throw Error(Status::bad_format, label + ": " + tiff.why(""));
    if (pages.empty()) throw Error(Status::bad_format, label + ": no full-resolution page");
    const Layout layout = page_layout(first, pages.size(), options, label);
    const ScalarType type = page_type(first, label);
    Grid grid;
    grid.type = type;
    grid.dims = {first.width, first.height, static_cast<std::int64_t>(layout.pages.size())};
    grid.spacing = options.spacing.value_or(layout.spacing);
    grid.origin = options.origin.value_or(Vec3{0, 0, 0});
    if (layout.pages.size() < 2) {
        throw Error(Status::bad_format, str_cat(label, ": 1 page of ", first.width, "x", first.height,
                                                " pixels; a volume needs at least 2 (a multi-page file, or a folder of numbered slices)"));
    }
    const std::uint64_t bytes = payload_bytes(grid.dims, type, label);
    // every page decodes to at least one byte per 1032 compressed (deflate's bound) or is raw:
    // a file far smaller than the declared volume is cut short or lying
    check_inflate_bound(input.size(), bytes, label, str_cat("the pages declare ", dims_text(grid.dims), " ", type_name(type),
                                                            " samples (", bytes, " bytes)"));
    Volume volume(type, grid.dims, grid.spacing, grid.origin);
    const std::size_t plane = static_cast<std::size_t>(bytes / static_cast<std::uint64_t>(grid.dims[2]));
    for (std::size_t k = 0; k < layout.pages.size(); ++k) {
        const tdir_t d = pages[layout.pages[k]];
        if (!TIFFSetDirectory(tif, d)) throw Error(Status::bad_format, str_cat(label, ": page ", d, " cannot be read: ", tiff.why("corrupt")));
        const Page p = read_page(tif);
        const std::string page_label = str_cat(label, ": page ", d);
        if (p.width != first.width || p.height != first.height) {
            throw Error(Status::bad_format, str_cat(page_label, " is ", p.width, "x", p.height, " pixels, page ", pages.front(), " ",
                                                    first.width, "x", first.height, "; expected one size for all pages"));
        }
        if (page_type(p, page_label) != type) {
            throw Error(Status::bad_format, str_cat(page_label, " holds ", type_name(page_type(p, page_label)), " samples, page ",
                                                    pages.front(), " ", type_name(type), "; expected one sample type for all pages"));
        }
        decode_page(tiff, p, type, volume.bytes() + k * plane, page_label);
    }
    return volume;
}

// ---- folders --------------------------------------------------------------------------------

/// The last run of digits in a file's stem, or nullopt.
std::optional<std::int64_t> name_number(const fs::path& file)
{
    const std::string stem = file.stem().string();
    std::size_t end = stem.size();
    while (end > 0 && !std::isdigit(static_cast<unsigned char>(stem[end - 1]))) --end;
    std::size_t start = end;
    while (start > 0 && std::isdigit(static_cast<unsigned char>(stem[start - 1]))) --start;
    std::int64_t n = 0;
    if (start == end || end - start > 15 || !parse_integer(std::string_view(stem).substr(start, end - start), n)) return std::nullopt;
    return n;
}

Volume read_tiff_folder(const fs::path& folder, const ReadOptions& options)
{
    const std::string label = folder.string();
    const std::vector<fs::path> files = folder_tiff_files(folder);
    if (files.empty()) throw Error(Status::unsupported_format, label + ": no .tif or .tiff file in the folder");
    std::vector<std::pair<std::int64_t, fs::path>> numbered;
    for (const fs::path& f : files) {
        const auto n = name_number(f);
        if (!n) {
            throw Error(Status::bad_format, str_cat(label, ": ", f.filename().string(),
                                                    " has no number in its name; expected slice files numbered in order (slice_001.tif, ...)"));
        }
        numbered.emplace_back(*n, f);
    }
    std::sort(numbered.begin(), numbered.end());
    for (std::size_t k = 0; k + 1 < numbered.size(); ++k) {
        const auto& [a, fa] = numbered[k];
        const auto& [b, fb] = numbered[k + 1];
        if (a == b) {
            throw Error(Status::bad_format, str_cat(label, ": ", fa.filename().string(), " and ", fb.filename().string(),
                                                    " have the same number ", a, "; expected one file per slice number"));
        }
        if (b != a + 1) {
            throw Error(Status::bad_format, str_cat(label, ": missing slice", b - a > 2 ? "s " : " ", a + 1, b - a > 2 ? str_cat(" to ", b - 1) : "",
                                                    " between ", fa.filename().string(), " and ", fb.filename().string(),
                                                    "; expected consecutive numbers"));
        }
    }
    if (options.frame && *options.frame != 0) {
        throw Error(Status::invalid_argument, str_cat(label, ": --frame ", *options.frame,
                                                      " is out of range; a folder of slices holds 1 frame (0)"));
    }
    if (numbered.size() < 2) {
        throw Error(Status::bad_format, str_cat(label, ": 1 slice file (", numbered.front().second.filename().string(),
                                                "); a volume needs at least 2"));
    }
    Volume volume;
    Page first;
    ScalarType type = ScalarType::u8;
    std::size_t plane = 0;
    for (std::size_t k = 0; k < numbered.size(); ++k) {
        const fs::path& f = numbered[k].second;
        const InputFile input(f, str_cat(label, ": ", f.filename().string()));
        const Tiff tiff(input);
        const Page p = read_page(tiff.get());
        const ScalarType t = page_type(p, input.label());
        if (k == 0) {
            first = p;
            type = t;
            Vec3 spacing{1, 1, 1};
            const auto ij = imagej_fields(p.description);
            if (!ij.empty()) {
                if (p.x_resolution) spacing[0] = 1 / *p.x_resolution;
                if (p.y_resolution) spacing[1] = 1 / *p.y_resolution;
                if (auto z = positive_number(field(ij, "spacing"))) spacing[2] = *z;
            }
            const Index3 dims{p.width, p.height, static_cast<std::int64_t>(numbered.size())};
            const std::uint64_t bytes = payload_bytes(dims, t, input.label());
            plane = static_cast<std::size_t>(bytes / dims[2]);
            volume = Volume(t, dims, options.spacing.value_or(spacing), options.origin.value_or(Vec3{0, 0, 0}));
        } else if (p.width != first.width || p.height != first.height || t != type) {
            throw Error(Status::bad_format,
                        str_cat(input.label(), " holds ", p.width, "x", p.height, " ", type_name(t), " samples, ",
                                numbered.front().second.filename().string(), " ", first.width, "x", first.height, " ", type_name(type),
                                "; expected one size and type for all slices"));
        }
        if (TIFFReadDirectory(tiff.get())) {
            if (!is_reduced(tiff.get())) {
                throw Error(Status::bad_format, input.label() + ": several pages in a slice file; expected one page per file in a folder");
            }
        }
        TIFFSetDirectory(tiff.get(), 0);
        decode_page(tiff, p, type, volume.bytes() + k * plane, input.label());
    }
    return volume;
}

} // namespace

Volume read_tiff(const fs::path& path, const ReadOptions& options)
{
    std::error_code ec;
    if (fs::is_directory(path, ec)) return read_tiff_folder(path, options);
    const InputFile input(path, path.string());
    return read_tiff_input(input, options);
}

Volume read_tiff_memory(std::string_view bytes, const std::string& label, const ReadOptions& options)
{
    const MemoryInput input(bytes, label);
    return read_tiff_input(input, options);
}

std::vector<fs::path> tiff_input_files(const fs::path& path)
{
    std::error_code ec;
    if (!fs::is_directory(path, ec)) return {path};
    try {
        return folder_tiff_files(path);
    } catch (const Error&) {
        return {path};
    }
}

#endif // CMC33_WITH_TIFF

} // namespace cmc33::io::detail
