// The structure of a DICOM file checked before GDCM parses it (contract in dicom_scan.hpp).
//
// The rules are the standard's, and where the standard leaves a choice the stricter side is
// taken wherever GDCM would otherwise guess, rewrite a length or assert:
// - a defined value length is even (PS3.5 7.1.1) and, for fixed-size binary VRs, a multiple of
//   the value size (PS3.5 6.2); it fits within its enclosing item, sequence or the file;
// - an undefined length (FFFFFFFFH) only on SQ, on UN (a sequence in Implicit VR Little Endian,
//   PS3.5 6.2.2), on items (PS3.5 7.5) and on encapsulated Pixel Data (PS3.5 A.4); in implicit
//   syntaxes an undefined length is a sequence (PS3.5 7.5.1);
// - items are (FFFE,E000), ended by their length or by (FFFE,E00D); undefined-length sequences
//   end with (FFFE,E0DD); both delimiters have length 0 (PS3.5 7.5.1, 7.5.2);
// - a defined-length value GDCM may open as a sequence (an Implicit VR element, or UN, whose
//   value starts with an item tag) is walked as one, in Implicit VR Little Endian as GDCM does.

#include "dicom_scan.hpp"

#include <array>
#include <cstdio>
#include <cstring>
#include <string_view>

#include "cmc33/error.hpp"
#include "volume_formats.hpp"

namespace cmc33::io::detail {

namespace {

constexpr std::uint32_t kUndefined = 0xFFFFFFFFu;

struct Syntax {
    bool explicit_vr = true;
    bool big = false;
};

constexpr Syntax kImplicitLittle{false, false};

/// A VR of PS3.5 Table 6.2-1: its code, whether its length field has 32 bits (PS3.5 7.1.2), and
/// the size of one value for fixed-size binary VRs (0 otherwise).
struct VrInfo {
    char code[3];
    bool long_length;
    unsigned value_size;
};

constexpr std::array<VrInfo, 34> kVrs{{
    {"AE", false, 0}, {"AS", false, 0}, {"AT", false, 4}, {"CS", false, 0}, {"DA", false, 0}, {"DS", false, 0},
    {"DT", false, 0}, {"FD", false, 8}, {"FL", false, 4}, {"IS", false, 0}, {"LO", false, 0}, {"LT", false, 0},
    {"OB", true, 0},  {"OD", true, 8},  {"OF", true, 4},  {"OL", true, 4},  {"OV", true, 8},  {"OW", true, 2},
    {"PN", false, 0}, {"SH", false, 0}, {"SL", false, 4}, {"SQ", true, 0},  {"SS", false, 2}, {"ST", false, 0},
    {"SV", true, 8},  {"TM", false, 0}, {"UC", true, 0},  {"UI", false, 0}, {"UL", false, 4}, {"UN", true, 0},
    {"UR", true, 0},  {"US", false, 2}, {"UT", true, 0},  {"UV", true, 8},
}};

const VrInfo* find_vr(const unsigned char* p)
{
    for (const VrInfo& v : kVrs) {
        if (v.code[0] == static_cast<char>(p[0]) && v.code[1] == static_cast<char>(p[1])) return &v;
    }
    return nullptr;
}

bool is_vr(const VrInfo* v, const char* code) { return v && std::strcmp(v->code, code) == 0; }

/// The transfer syntaxes walked, each with its encoding (PS3.5 A.1 to A.4; PS3.6 Table A-1).
struct KnownSyntax {
    const char* uid;
    Syntax syntax;
    bool encapsulated;
};

constexpr std::array<KnownSyntax, 14> kSyntaxes{{
    {"1.2.840.10008.1.2", {false, false}, false},      // Implicit VR Little Endian
    {"1.2.840.10008.1.2.1", {true, false}, false},     // Explicit VR Little Endian
    {"1.2.840.10008.1.2.2", {true, true}, false},      // Explicit VR Big Endian (retired)
    {"1.2.840.10008.1.2.4.50", {true, false}, true},   // JPEG Baseline
    {"1.2.840.10008.1.2.4.51", {true, false}, true},   // JPEG Extended
    {"1.2.840.10008.1.2.4.57", {true, false}, true},   // JPEG Lossless
    {"1.2.840.10008.1.2.4.70", {true, false}, true},   // JPEG Lossless, first-order prediction
    {"1.2.840.10008.1.2.4.80", {true, false}, true},   // JPEG-LS Lossless
    {"1.2.840.10008.1.2.4.81", {true, false}, true},   // JPEG-LS Near-Lossless
    {"1.2.840.10008.1.2.4.90", {true, false}, true},   // JPEG 2000 Lossless
    {"1.2.840.10008.1.2.4.91", {true, false}, true},   // JPEG 2000
    {"1.2.840.10008.1.2.4.92", {true, false}, true},   // JPEG 2000 Part 2 Lossless
    {"1.2.840.10008.1.2.4.93", {true, false}, true},   // JPEG 2000 Part 2
    {"1.2.840.10008.1.2.5", {true, false}, true},      // RLE Lossless
}};

std::string tag_text(std::uint16_t group, std::uint16_t element)
{
    char s[16];
    std::snprintf(s, sizeof s, "(%04x,%04x)", group, element);
    return s;
}

/// Reads through a window of the input: element headers are small and many.
class Window {
public:
    explicit Window(const ByteInput& input) : input_(input) {}

    /// `count` (at most kChunk) bytes at `at`; the caller checked that they lie within the input.
    const unsigned char* get(std::uint64_t at, std::size_t count)
    {
        if (at < start_ || at + count > start_ + buffer_.size()) {
            start_ = at;
            buffer_ = input_.read_string(at, kChunk);
        }
        return reinterpret_cast<const unsigned char*>(buffer_.data() + (at - start_));
    }

private:
    static constexpr std::size_t kChunk = 64 * 1024;
    const ByteInput& input_;
    std::string buffer_;
    std::uint64_t start_ = 0;
};

/// One element's header.
struct Element {
    std::uint16_t group = 0, element = 0;
    const VrInfo* vr = nullptr; // explicit syntaxes, not for items and delimiters
    std::uint32_t length = 0;
    std::uint64_t at = 0;       // the tag's offset
    std::uint64_t value = 0;    // the value's offset

    bool is(std::uint16_t g, std::uint16_t e) const { return group == g && element == e; }
    bool undefined() const { return length == kUndefined; }
};

/// Where a walk is: what ends the data set being walked.
enum class Until { end, item_delimiter };

class Scanner {
public:
    Scanner(const ByteInput& input, const DicomVrCheck& vr_check) : input_(input), window_(input), size_(input.size()), vr_check_(vr_check) {}

    DicomLayout run()
    {
        if (size_ < 132 || std::memcmp(window_.get(128, 4), "DICM", 4) != 0) {
            throw Error(Status::bad_format,
                        label() + ": not a DICOM file: no \"DICM\" mark at byte 128; expected a DICOM Part 10 file (a 128-byte preamble, \"DICM\", "
                                  "the file meta group; PS3.10 7.1)");
        }
        const std::uint64_t at = meta(132);
        if (at == size_) {
            // GDCM reads one tag past the meta group, and asserts when the file ends there
            throw Error(Status::truncated_file, str_cat(label(), ": the file ends at byte ", at,
                                                        " after the file meta group; expected the data set (file cut short?)"));
        }
        dataset(at, size_, syntax_, 0, false, Until::end);
        return layout_;
    }

private:
    std::string label() const { return input_.label(); }

    [[noreturn]] void fail(Status status, const Element& e, const std::string& what) const
    {
        throw Error(status, str_cat(label(), ": DICOM element ", tag_text(e.group, e.element), " at byte ", e.at, ": ", what));
    }

    std::uint16_t u16(const unsigned char* p, bool big) const
    {
        return big ? static_cast<std::uint16_t>(p[0] << 8 | p[1]) : static_cast<std::uint16_t>(p[1] << 8 | p[0]);
    }
    std::uint32_t u32(const unsigned char* p, bool big) const
    {
        const std::uint32_t b0 = p[0], b1 = p[1], b2 = p[2], b3 = p[3];
        return big ? b0 << 24 | b1 << 16 | b2 << 8 | b3 : b3 << 24 | b2 << 16 | b1 << 8 | b0;
    }

    /// The header of the element at `at`, which must lie before `end`.
    Element header(std::uint64_t at, std::uint64_t end, Syntax s, const char* what)
    {
        Element e;
        e.at = at;
        if (end - at < 8) {
            if (end - at >= 4) {
                const unsigned char* p = window_.get(at, 4);
                e.group = u16(p, s.big);
                e.element = u16(p + 2, s.big);
            }
            throw Error(Status::truncated_file,
                        str_cat(label(), ": ", end - at, " bytes at byte ", at, " where ", what,
                                " should start (8 or more bytes); the ", end == size_ ? "file" : "enclosing item",
                                " ends there (file cut short?)"));
        }
        const unsigned char* p = window_.get(at, 12 <= end - at ? 12 : 8);
        e.group = u16(p, s.big);
        e.element = u16(p + 2, s.big);
        if (!s.explicit_vr || e.group == 0xFFFE) {
            // implicit VR, and items and delimiters in any syntax: tag and a 32-bit length (PS3.5 7.1.3, 7.5)
            e.length = u32(p + 4, s.big);
            e.value = at + 8;
            return e;
        }
        e.vr = find_vr(p + 4);
        if (!e.vr) {
            fail(Status::bad_format, e,
                 str_cat("VR ", quote_bytes(std::string_view(reinterpret_cast<const char*>(p + 4), 2), 8),
                         " is not one of PS3.5 Table 6.2-1; expected an explicit VR (PS3.5 7.1.2)"));
        }
        if (e.vr->long_length) {
            if (end - at < 12) {
                throw Error(Status::truncated_file, str_cat(label(), ": DICOM element ", tag_text(e.group, e.element), " at byte ", at,
                                                            ": its 12-byte header passes the end of the ",
                                                            end == size_ ? "file" : "enclosing item", " (file cut short?)"));
            }
            e.length = u32(p + 8, s.big);
            e.value = at + 12;
        } else {
            e.length = u16(p + 6, s.big);
            e.value = at + 8;
        }
        return e;
    }

    /// A defined length: even, a whole number of values, within `end`.
    void check_length(const Element& e, std::uint64_t end, const char* container)
    {
        if (e.length > end - e.value) {
            fail(Status::truncated_file, e,
                 str_cat("value length ", e.length, " passes the end of the ", container, " (", end - e.value,
                         " bytes remain); expected a length within it (PS3.5 7.1.1; file cut short?)"));
        }
        if (e.length % 2 != 0) fail(Status::bad_format, e, str_cat("odd value length ", e.length, "; expected an even length (PS3.5 7.1.1)"));
        if (e.vr && e.vr->value_size > 1 && e.length % e.vr->value_size != 0) {
            fail(Status::bad_format, e,
                 str_cat("value length ", e.length, " of VR ", e.vr->code, " is not a multiple of its ", e.vr->value_size,
                         "-byte values (PS3.5 6.2)"));
        }
    }

    /// The file meta group from `at` (PS3.10 7.1: explicit VR little endian). Returns where the
    /// data set starts.
    std::uint64_t meta(std::uint64_t at)
    {
        constexpr Syntax little{true, false};
        std::uint64_t group_start = 0, group_length = 0;
        bool has_group_length = false, has_syntax = false;
        while (at < size_) {
            if (size_ - at >= 2 && u16(window_.get(at, 2), false) != 0x0002) break;
            const Element e = header(at, size_, little, "a file meta element");
            if (e.undefined() || is_vr(e.vr, "SQ")) fail(Status::bad_format, e, "a sequence or undefined length in the file meta group (PS3.10 7.1)");
            check_length(e, size_, "file");
            if (e.is(0x0002, 0x0000) && e.length == 4 && is_vr(e.vr, "UL")) {
                has_group_length = true;
                group_length = u32(window_.get(e.value, 4), false);
                group_start = e.value + 4;
            }
            if (e.is(0x0002, 0x0010)) {
                std::string uid = input_.read_string(e.value, e.length);
                if (!uid.empty() && uid.back() == '\0') uid.pop_back(); // UI padding (PS3.5 9.1)
                layout_.transfer_syntax = uid;
                has_syntax = true;
            }
            at = e.value + e.length;
        }
        Element where;
        where.at = at;
        where.group = 0x0002;
        if (!has_syntax) {
            throw Error(Status::bad_format, str_cat(label(), ": no TransferSyntaxUID (0002,0010) in the file meta group before byte ", at,
                                                    "; expected the file meta group after \"DICM\" (PS3.10 7.1)"));
        }
        if (has_group_length && at - group_start != group_length) {
            fail(Status::bad_format, where,
                 str_cat("the file meta group ends here, ", at - group_start, " bytes after (0002,0000), which says ", group_length,
                         "; expected them to agree (PS3.10 7.1)"));
        }
        const std::string& uid = layout_.transfer_syntax;
        if (uid == "1.2.840.10008.1.2.1.99") {
            throw Error(Status::unsupported_format,
                        label() + ": transfer syntax Deflated Explicit VR Little Endian (1.2.840.10008.1.2.1.99) is not read "
                                  "(its elements cannot be checked before parsing); expected it inflated, e.g. with "
                                  "`dcmconv +te` or `gdcmconv --explicit`");
        }
        for (const KnownSyntax& k : kSyntaxes) {
            if (uid == k.uid) {
                syntax_ = k.syntax;
                layout_.encapsulated = k.encapsulated;
                return at;
            }
        }
        throw Error(Status::unsupported_format,
                    str_cat(label(), ": transfer syntax ", quote_bytes(uid, 80),
                            " is not read; expected Implicit or Explicit VR Little Endian, Explicit VR Big Endian, JPEG, "
                            "JPEG-LS, JPEG 2000 or RLE Lossless"));
    }

    /// The value of a defined-length element that GDCM may open as a sequence: an Implicit VR
    /// element, or UN, whose value starts with an item tag or a byte-swapped one.
    bool looks_like_sequence(const Element& e)
    {
        if (e.length < 4 || e.group == 0x7FE0) return false;
        const unsigned char* p = window_.get(e.value, 4);
        static constexpr unsigned char kStarts[4][4] = {
            {0xFE, 0xFF, 0x00, 0xE0}, {0xFF, 0xFE, 0xE0, 0x00}, {0xFE, 0xFF, 0xDD, 0xE0}, {0xFF, 0xFE, 0xE0, 0xDD}};
        for (const auto& s : kStarts) {
            if (std::memcmp(p, s, 4) == 0) return true;
        }
        return false;
    }

    /// The elements of a data set from `at`: up to `end`, or up to an item delimiter. `defined`:
    /// within a defined-length item or sequence. Returns where it ended.
    std::uint64_t dataset(std::uint64_t at, std::uint64_t end, Syntax s, int depth, bool defined, Until until)
    {
        const bool top = depth == 0;
        const char* container = end == size_ ? "file" : "enclosing item";
        while (true) {
            if (at == end) {
                if (until == Until::end) return at;
                throw Error(Status::truncated_file,
                            str_cat(label(), ": the ", container, " ends at byte ", at,
                                    " inside an item of undefined length; expected its Item Delimitation Item (FFFE,E00D) "
                                    "(PS3.5 7.5.2; file cut short?)"));
            }
            const Element e = header(at, end, s, "a data element");
            if (e.group == 0xFFFE) {
                if (e.is(0xFFFE, 0xE00D) && until == Until::item_delimiter) {
                    if (e.length != 0) fail(Status::bad_format, e, str_cat("Item Delimitation Item of length ", e.length, "; expected 0 (PS3.5 7.5.2)"));
                    return e.value;
                }
                fail(Status::bad_format, e,
                     str_cat(e.is(0xFFFE, 0xE000)   ? "an Item"
                             : e.is(0xFFFE, 0xE00D) ? "an Item Delimitation Item"
                             : e.is(0xFFFE, 0xE0DD) ? "a Sequence Delimitation Item"
                                                    : "a tag of the delimiter group FFFE",
                             " among data elements; expected ",
                             until == Until::item_delimiter ? "a data element or (FFFE,E00D) ending the item" : "a data element",
                             " (PS3.5 7.5)"));
            }
            if (e.group == 0xFEFF || e.is(0x00FF, 0x4AA5)) {
                fail(Status::bad_format, e, "a byte-swapped item tag or a vendor marker GDCM reinterprets; expected a data element");
            }
            if (e.vr && vr_check_) {
                const std::string expected = vr_check_(e.group, e.element, e.vr->code);
                if (!expected.empty()) fail(Status::bad_format, e, str_cat("VR ", e.vr->code, "; expected ", expected, " (PS3.6)"));
            }
            const bool pixel_data = e.is(0x7FE0, 0x0010);
            if (pixel_data && s.explicit_vr && !(is_vr(e.vr, "OB") || is_vr(e.vr, "OW") || (is_vr(e.vr, "UN") && !e.undefined()))) {
                fail(Status::bad_format, e, str_cat("Pixel Data with VR ", e.vr->code, "; expected OB or OW (PS3.5 8.2, A.4)"));
            }
            if (e.undefined()) {
                if (pixel_data) {
                    if (!layout_.encapsulated) {
                        fail(Status::bad_format, e,
                             "Pixel Data of undefined length in a native transfer syntax; expected a defined length "
                             "(encapsulated Pixel Data only in compressed syntaxes, PS3.5 A.4)");
                    }
                    at = fragments(e, end, top);
                } else if (!s.explicit_vr || is_vr(e.vr, "SQ")) {
                    at = sequence(e, end, s, depth + 1, defined);
                } else if (is_vr(e.vr, "UN")) {
                    if (s.big) fail(Status::unsupported_format, e, "UN of undefined length in a big-endian data set; expected a defined length");
                    if (defined) {
                        fail(Status::unsupported_format, e,
                             "UN of undefined length inside a defined-length item; expected it in an item of undefined length "
                             "or at the top level");
                    }
                    at = sequence(e, end, kImplicitLittle, depth + 1, defined);
                } else {
                    fail(Status::bad_format, e,
                         str_cat("undefined value length (FFFFFFFFH) on VR ", e.vr->code,
                                 "; expected it only on SQ, UN, items and encapsulated Pixel Data (PS3.5 7.1.2, 7.5, A.4)"));
                }
                continue;
            }
            check_length(e, end, container);
            if (pixel_data && top) {
                if (layout_.encapsulated) {
                    fail(Status::bad_format, e,
                         str_cat("Pixel Data of defined length ", e.length,
                                 " in a compressed transfer syntax; expected encapsulated Pixel Data of undefined length (PS3.5 A.4)"));
                }
                layout_.pixel_bytes = e.length;
            }
            if (is_vr(e.vr, "SQ")) {
                sequence(e, e.value + e.length, s, depth + 1, true);
            } else if ((!s.explicit_vr || is_vr(e.vr, "UN")) && looks_like_sequence(e)) {
                sequence(e, e.value + e.length, kImplicitLittle, depth + 1, true);
            }
            at = e.value + e.length;
        }
    }

    /// The items of sequence `sq` (PS3.5 7.5). `end`: the sequence's end when its length is
    /// defined, else the end of what encloses it. Returns where the sequence ended.
    std::uint64_t sequence(const Element& sq, std::uint64_t end, Syntax s, int depth, bool defined)
    {
        if (depth > kMaxDicomNesting) {
            fail(Status::bad_format, sq, str_cat("sequences nested more than ", kMaxDicomNesting, " deep; expected fewer levels"));
        }
        const bool undefined = sq.undefined();
        std::uint64_t at = sq.value;
        while (true) {
            if (!undefined && at == end) return at;
            if (undefined && at == end) {
                throw Error(Status::truncated_file,
                            str_cat(label(), ": the sequence ", tag_text(sq.group, sq.element), " at byte ", sq.at,
                                    " reaches byte ", at, " without its Sequence Delimitation Item (FFFE,E0DD) (PS3.5 7.5.2; file cut short?)"));
            }
            const Element item = header(at, end, s, "an item");
            if (undefined && item.is(0xFFFE, 0xE0DD)) {
                if (item.length != 0) fail(Status::bad_format, item, str_cat("Sequence Delimitation Item of length ", item.length, "; expected 0 (PS3.5 7.5.2)"));
                return item.value;
            }
            if (!item.is(0xFFFE, 0xE000)) {
                fail(Status::bad_format, item,
                     str_cat("in the sequence ", tag_text(sq.group, sq.element), " at byte ", sq.at, ": expected an Item (FFFE,E000)",
                             undefined ? " or the Sequence Delimitation Item (FFFE,E0DD)" : "", " (PS3.5 7.5)"));
            }
            if (item.undefined()) {
                at = dataset(item.value, end, s, depth, defined || !undefined, Until::item_delimiter);
            } else {
                check_length(item, end, undefined ? (end == size_ ? "file" : "enclosing item") : "sequence");
                dataset(item.value, item.value + item.length, s, depth, true, Until::end);
                at = item.value + item.length;
            }
        }
    }

    /// Encapsulated Pixel Data (PS3.5 A.4): the Basic Offset Table item, fragment items of
    /// defined length, the Sequence Delimitation Item. Returns where it ended.
    std::uint64_t fragments(const Element& pd, std::uint64_t end, bool top)
    {
        std::uint64_t at = pd.value, total = 0;
        for (std::size_t index = 0;; ++index) {
            if (at == end) {
                throw Error(Status::truncated_file,
                            str_cat(label(), ": the encapsulated Pixel Data at byte ", pd.at, " reaches byte ", at,
                                    " without its Sequence Delimitation Item (FFFE,E0DD) (PS3.5 A.4; file cut short?)"));
            }
            const Element item = header(at, end, {false, false}, "a Pixel Data item");
            if (index > 0 && item.is(0xFFFE, 0xE0DD)) {
                if (item.length != 0) fail(Status::bad_format, item, str_cat("Sequence Delimitation Item of length ", item.length, "; expected 0 (PS3.5 A.4)"));
                if (top) layout_.pixel_bytes = total;
                return item.value;
            }
            if (!item.is(0xFFFE, 0xE000)) {
                fail(Status::bad_format, item,
                     str_cat("in the encapsulated Pixel Data at byte ", pd.at, ": expected ",
                             index == 0 ? "the Basic Offset Table item (FFFE,E000)" : "a fragment item (FFFE,E000) or (FFFE,E0DD)", " (PS3.5 A.4)"));
            }
            if (item.undefined()) fail(Status::bad_format, item, "a Pixel Data item of undefined length; expected a defined length (PS3.5 A.4)");
            check_length(item, end, end == size_ ? "file" : "enclosing item");
            if (index == 0 && item.length % 4 != 0) {
                fail(Status::bad_format, item,
                     str_cat("Basic Offset Table of ", item.length, " bytes; expected 32-bit offsets (a multiple of 4 bytes, PS3.5 A.4)"));
            }
            if (index > 0) {
                total += item.length;
                if (top) layout_.fragments.emplace_back(item.value, item.length);
            }
            at = item.value + item.length;
        }
    }

    const ByteInput& input_;
    Window window_;
    std::uint64_t size_;
    const DicomVrCheck& vr_check_;
    Syntax syntax_;
    DicomLayout layout_;
};

} // namespace

DicomLayout scan_dicom(const ByteInput& input, const DicomVrCheck& vr_check)
{
    return Scanner(input, vr_check).run();
}

void check_rle(const ByteInput& input, const DicomLayout& layout, std::uint64_t frames, std::uint64_t rows, std::uint64_t columns,
               unsigned segments)
{
    const std::string& label = input.label();
    if (layout.fragments.size() != frames) {
        throw Error(Status::bad_format, str_cat(label, ": RLE Pixel Data with ", layout.fragments.size(), " fragments for ", frames,
                                                " frame", frames == 1 ? "" : "s", "; expected one fragment per frame (PS3.5 G.2)"));
    }
    if (segments < 1 || segments > 15) {
        throw Error(Status::bad_format, str_cat(label, ": RLE Pixel Data would need ", segments,
                                                " segments per frame (samples x bytes per sample); expected 1 to 15 (PS3.5 G.2)"));
    }
    const std::uint64_t plane = rows * columns;
    for (std::size_t f = 0; f < layout.fragments.size(); ++f) {
        const auto [at, length] = layout.fragments[f];
        const std::string frame = str_cat(label, ": RLE frame ", f + 1, " at byte ", at);
        if (length < 64) throw Error(Status::bad_format, str_cat(frame, ": ", length, " bytes; expected the 64-byte RLE header first (PS3.5 G.5)"));
        const std::string bytes = input.read_string(at, length);
        const auto u32 = [&](std::size_t i) {
            const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + 4 * i;
            return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
        };
        if (u32(0) != segments) {
            throw Error(Status::bad_format, str_cat(frame, ": ", u32(0), " segments; expected ", segments,
                                                    " (one per byte of each sample, PS3.5 G.2)"));
        }
        for (unsigned s = 0; s < segments; ++s) {
            const std::uint64_t start = u32(1 + s), stop = s + 1 < segments ? u32(2 + s) : length;
            if (start < 64 || start >= stop || stop > length || (s == 0 && start != 64)) {
                throw Error(Status::bad_format, str_cat(frame, ": segment ", s + 1, " spans bytes ", start, " to ", stop, " of the ", length,
                                                        "-byte fragment; expected increasing offsets after the 64-byte header (PS3.5 G.5)"));
            }
            // PackBits (PS3.5 G.3.1): n in 0..127 copies n+1 bytes, -127..-1 repeats the next byte 1-n times, -128 is a no-op
            std::uint64_t out = 0, i = start;
            while (out < plane && i < stop) {
                const auto n = static_cast<signed char>(bytes[i++]);
                std::uint64_t count = 0;
                if (n >= 0) {
                    count = static_cast<std::uint64_t>(n) + 1;
                    if (stop - i < count) break;
                    i += count;
                } else if (n != -128) {
                    count = static_cast<std::uint64_t>(1 - n);
                    if (i == stop) break;
                    ++i;
                }
                out += count;
            }
            if (out != plane) {
                throw Error(Status::bad_format, str_cat(frame, ": segment ", s + 1, out < plane ? " ends after " : " runs past ",
                                                        out < plane ? out : plane, " of its ", plane, " bytes (", columns, "x", rows,
                                                        "); expected each segment to decode to one byte per pixel (PS3.5 G.3)"));
            }
        }
    }
}

} // namespace cmc33::io::detail
