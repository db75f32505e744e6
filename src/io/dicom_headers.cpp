// The DICOM reader's first pass through GDCM (dicom_gdcm.hpp): the tags it reads, their values,
// and each file's header up to its Pixel Data (GDCM stops there), keeping what grouping, sorting
// and the frame need; and the input's files (a folder, a DICOMDIR, a file) as sources.

#if CMC33_WITH_GDCM

#include "dicom_gdcm.hpp"

#include "dicom.hpp"
#include "dicom_scan.hpp"
#include "tiff.hpp"
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>
#include "cmc33/error.hpp"
#include "atomic_file.hpp"
#include "byte_source.hpp"
#include "portability.hpp"
#include "volume_formats.hpp"
#include <gdcmDataSet.h>
#include <gdcmDictEntry.h>
#include <gdcmDicts.h>
#include <gdcmGlobal.h>
#include <gdcmFile.h>
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmReader.h>
#include <gdcmSequenceOfItems.h>
#include <gdcmTrace.h>
#include <gdcmTransferSyntax.h>

namespace cmc33::io::detail::dicom_gdcm {

// ---- tags -----------------------------------------------------------------------------------

const gdcm::Tag kTransferSyntaxTag(0x0002, 0x0010);
const gdcm::Tag kMediaStorageTag(0x0002, 0x0002);
const gdcm::Tag kModality(0x0008, 0x0060);
const gdcm::Tag kSeriesDescription(0x0008, 0x103e);
const gdcm::Tag kSeriesUid(0x0020, 0x000e);
const gdcm::Tag kInstanceNumber(0x0020, 0x0013);
const gdcm::Tag kPosition(0x0020, 0x0032);    // ImagePositionPatient
const gdcm::Tag kOrientation(0x0020, 0x0037); // ImageOrientationPatient
const gdcm::Tag kSamplesPerPixel(0x0028, 0x0002);
const gdcm::Tag kPhotometric(0x0028, 0x0004);
const gdcm::Tag kNumberOfFrames(0x0028, 0x0008);
const gdcm::Tag kRows(0x0028, 0x0010);
const gdcm::Tag kColumns(0x0028, 0x0011);
const gdcm::Tag kPixelSpacing(0x0028, 0x0030);
const gdcm::Tag kImagerPixelSpacing(0x0018, 0x1164);
const gdcm::Tag kBitsAllocated(0x0028, 0x0100);
const gdcm::Tag kBitsStored(0x0028, 0x0101);
const gdcm::Tag kHighBit(0x0028, 0x0102);
const gdcm::Tag kPixelRepresentation(0x0028, 0x0103);
const gdcm::Tag kIntercept(0x0028, 0x1052);
const gdcm::Tag kSlope(0x0028, 0x1053);
const gdcm::Tag kSharedGroups(0x5200, 0x9229);
const gdcm::Tag kPerFrameGroups(0x5200, 0x9230);
const gdcm::Tag kPlanePositionSeq(0x0020, 0x9113);
const gdcm::Tag kPlaneOrientationSeq(0x0020, 0x9116);
const gdcm::Tag kPixelMeasuresSeq(0x0028, 0x9110);
const gdcm::Tag kValueTransformSeq(0x0028, 0x9145);
const gdcm::Tag kPixelData(0x7fe0, 0x0010);
const gdcm::Tag kFloatPixelData(0x7fe0, 0x0008);
const gdcm::Tag kDoubleFloatPixelData(0x7fe0, 0x0009);

constexpr std::string_view kDicomdirClass = "1.2.840.10008.1.3.10";

/// GDCM's own warnings and errors go to stderr unless turned off: ours say it in one line.
void quiet_gdcm()
{
    static const bool done = [] {
        gdcm::Trace::SetDebug(false);
        gdcm::Trace::SetWarning(false);
        gdcm::Trace::SetError(false);
        return true;
    }();
    (void)done;
}

// ---- values ---------------------------------------------------------------------------------

/// The bytes of a value ("" for a missing or empty one, or a sequence).
std::string_view raw_value(const gdcm::DataSet& ds, const gdcm::Tag& tag)
{
    if (!ds.FindDataElement(tag)) return {};
    const gdcm::DataElement& de = ds.GetDataElement(tag);
    const gdcm::ByteValue* bv = de.GetByteValue();
    if (!bv || !bv->GetPointer()) return {};
    return std::string_view(bv->GetPointer(), bv->GetLength());
}

/// A text value without its padding (blanks and NULs).
std::string text_value(const gdcm::DataSet& ds, const gdcm::Tag& tag)
{
    std::string_view v = raw_value(ds, tag);
    while (!v.empty() && (v.back() == '\0' || v.back() == ' ')) v.remove_suffix(1);
    while (!v.empty() && v.front() == ' ') v.remove_prefix(1);
    return std::string(v);
}

/// The numbers of a DS or IS value ("a\b\c"); nullopt when any is not a finite number.
std::optional<std::vector<double>> numbers_value(const gdcm::DataSet& ds, const gdcm::Tag& tag)
{
    const std::string text = text_value(ds, tag);
    if (text.empty()) return std::nullopt;
    std::vector<double> out;
    std::size_t start = 0;
    while (true) {
        const std::size_t stop = text.find('\\', start);
        const std::string_view word = trim(std::string_view(text).substr(start, stop == std::string::npos ? std::string::npos : stop - start));
        double v = 0;
        if (!parse_real(word, v) || !std::isfinite(v)) return std::nullopt;
        out.push_back(v);
        if (stop == std::string::npos) break;
        start = stop + 1;
    }
    return out;
}

/// An unsigned short (US) value. GDCM holds binary values in little-endian order, whatever the
/// transfer syntax (it swaps those of Explicit VR Big Endian as it reads them).
std::optional<unsigned> us_value(const gdcm::DataSet& ds, const gdcm::Tag& tag)
{
    const std::string_view v = raw_value(ds, tag);
    if (v.size() != 2) return std::nullopt;
    const auto b0 = static_cast<unsigned char>(v[0]), b1 = static_cast<unsigned char>(v[1]);
    return unsigned{b1} << 8 | b0;
}

/// The first item's data set of a sequence, or nullptr.
const gdcm::DataSet* first_item(const gdcm::DataSet& ds, const gdcm::Tag& tag,
                                std::vector<gdcm::SmartPointer<gdcm::SequenceOfItems>>& keep)
{
    if (!ds.FindDataElement(tag)) return nullptr;
    gdcm::SmartPointer<gdcm::SequenceOfItems> sq = ds.GetDataElement(tag).GetValueAsSQ();
    if (!sq || sq->GetNumberOfItems() < 1) return nullptr;
    keep.push_back(sq);
    return &sq->GetItem(1).GetNestedDataSet();
}

std::string vec_text(const Vec3& v)
{
    return str_cat("(", format_real(v[0]), ", ", format_real(v[1]), ", ", format_real(v[2]), ")");
}

// ---- headers --------------------------------------------------------------------------------

void read_geometry(const gdcm::DataSet& ds, Geometry& g)
{
    if (auto p = numbers_value(ds, kPosition); p && p->size() == 3) g.position = Vec3{(*p)[0], (*p)[1], (*p)[2]};
    if (auto o = numbers_value(ds, kOrientation); o && o->size() == 6) {
        std::array<double, 6> a{};
        std::copy(o->begin(), o->end(), a.begin());
        g.orientation = a;
    }
    if (auto s = numbers_value(ds, kPixelSpacing); s && s->size() == 2) g.pixel_spacing = std::array<double, 2>{(*s)[0], (*s)[1]};
    if (auto s = numbers_value(ds, kSlope); s && s->size() == 1) g.slope = (*s)[0];
    if (auto s = numbers_value(ds, kIntercept); s && s->size() == 1) g.intercept = (*s)[0];
}

/// Fills `g` from a functional groups item (Enhanced CT/MR, PS3.3 C.7.6.16): what the item has
/// replaces what `g` holds.
void read_functional_groups(const gdcm::DataSet& item, Geometry& g)
{
    std::vector<gdcm::SmartPointer<gdcm::SequenceOfItems>> keep;
    if (const gdcm::DataSet* ds = first_item(item, kPlanePositionSeq, keep)) {
        Geometry h;
        read_geometry(*ds, h);
        if (h.position) g.position = h.position;
    }
    if (const gdcm::DataSet* ds = first_item(item, kPlaneOrientationSeq, keep)) {
        Geometry h;
        read_geometry(*ds, h);
        if (h.orientation) g.orientation = h.orientation;
    }
    if (const gdcm::DataSet* ds = first_item(item, kPixelMeasuresSeq, keep)) {
        Geometry h;
        read_geometry(*ds, h);
        if (h.pixel_spacing) g.pixel_spacing = h.pixel_spacing;
    }
    if (const gdcm::DataSet* ds = first_item(item, kValueTransformSeq, keep)) {
        if (ds->FindDataElement(kSlope) || ds->FindDataElement(kIntercept)) {
            Geometry h;
            read_geometry(*ds, h);
            g.slope = h.slope;
            g.intercept = h.intercept;
        }
    }
}

/// Opens a GDCM reader on a source. The stream must outlive the reader's use.
void open(gdcm::Reader& reader, const Source& source, std::unique_ptr<std::istringstream>& stream)
{
    if (source.in_memory) {
        stream = std::make_unique<std::istringstream>(std::string(source.bytes));
        reader.SetStream(*stream);
    } else {
        reader.SetFileName(source.path.c_str());
    }
}

bool is_native(const gdcm::TransferSyntax& ts)
{
    return ts == gdcm::TransferSyntax::ImplicitVRLittleEndian || ts == gdcm::TransferSyntax::ExplicitVRLittleEndian ||
           ts == gdcm::TransferSyntax::ExplicitVRBigEndian;
}

/// The bytes of a source from `offset` (at most `count`).
std::string source_bytes(const Source& source, std::uint64_t offset, std::uint64_t count)
{
    if (source.in_memory) {
        if (offset >= source.bytes.size()) return {};
        return std::string(source.bytes.substr(static_cast<std::size_t>(offset), static_cast<std::size_t>(count)));
    }
    const InputFile file(source.path, source.label);
    return file.read_string(offset, count);
}

/// GDCM reads image attributes through typed accessors that assert when an element's VR is not
/// the data dictionary's (PS3.6): such a VR is refused first. Private tags are not judged.
std::string dictionary_vr(std::uint16_t group, std::uint16_t element, std::string_view vr)
{
    if (group % 2 != 0) return {};
    // repeating groups (overlays 60xx, curves 50xx) are listed under their first group
    const std::uint16_t base = (group & 0xFF00) == 0x6000 || (group & 0xFF00) == 0x5000 ? static_cast<std::uint16_t>(group & 0xFF00) : group;
    const gdcm::DictEntry& entry = gdcm::Global::GetInstance().GetDicts().GetDictEntry(gdcm::Tag(base, element));
    const gdcm::VR expected = entry.GetVR();
    if (expected == gdcm::VR::INVALID || expected == gdcm::VR::VR_END) return {};
    const std::string code(vr);
    if (expected.Compatible(gdcm::VR(gdcm::VR::GetVRTypeFromFile(code.c_str())))) return {};
    const char* name = gdcm::VR::GetVRString(expected);
    return name ? name : "the data dictionary's VR";
}

/// The element structure of a source checked before GDCM sees it (dicom_scan.hpp).
DicomLayout scan(const Source& source)
{
    if (source.in_memory) return scan_dicom(MemoryInput(source.bytes, source.label), dictionary_vr);
    return scan_dicom(InputFile(source.path, source.label), dictionary_vr);
}

/// Reads a file's header up to its Pixel Data (GDCM reads no further).
Header read_header(const Source& source, std::size_t index)
{
    quiet_gdcm();
    Header h;
    h.source = index;
    h.label = source.label;
    h.layout = scan(source);
    gdcm::Reader reader;
    std::unique_ptr<std::istringstream> stream;
    open(reader, source, stream);
    bool ok = false;
    try {
        ok = reader.ReadUpToTag(kPixelData);
    } catch (...) { // GDCM also throws plain strings
        ok = false;
    }
    if (!ok) {
        throw Error(Status::bad_format, source.label + ": not a DICOM file GDCM can read (expected a DICOM Part 10 "
                                                       "file: a 128-byte preamble, \"DICM\", then the data set)");
    }
    const gdcm::File& file = reader.GetFile();
    const gdcm::DataSet& meta = file.GetHeader();
    const gdcm::DataSet& ds = file.GetDataSet();
    h.ts = file.GetHeader().GetDataSetTransferSyntax();
    h.transfer_uid = text_value(meta, kTransferSyntaxTag);
    if (text_value(meta, kMediaStorageTag) == kDicomdirClass) {
        h.modality = "DICOMDIR";
        return h;
    }
    h.series = text_value(ds, kSeriesUid);
    h.description = text_value(ds, kSeriesDescription);
    h.modality = text_value(ds, kModality);
    h.instance = text_value(ds, kInstanceNumber);
    h.photometric = text_value(ds, kPhotometric);
    h.has_pixels = ds.FindDataElement(kPixelData);
    h.float_pixels = ds.FindDataElement(kFloatPixelData) || ds.FindDataElement(kDoubleFloatPixelData);
    if (h.has_pixels && is_native(h.ts)) {
        // GDCM stops after the Pixel Data element, its value skipped: the samples are the `length`
        // bytes before that point, if the element's own header says so (else GDCM reads them).
        const gdcm::VL vl = ds.GetDataElement(kPixelData).GetVL();
        const std::uint64_t end = reader.GetStreamCurrentPosition();
        const bool explicit_vr = h.ts != gdcm::TransferSyntax::ImplicitVRLittleEndian;
        const bool big = h.ts == gdcm::TransferSyntax::ExplicitVRBigEndian;
        const std::uint64_t length = static_cast<std::uint32_t>(vl), header = explicit_vr ? 12 : 8;
        if (!vl.IsUndefined() && end >= length + header) {
            const std::string head = source_bytes(source, end - length - header, header);
            const auto byte = [&](std::size_t i) { return static_cast<std::uint32_t>(static_cast<unsigned char>(head[i])); };
            const bool tag_ok = head.size() == header && (big ? head.compare(0, 4, "\x7f\xe0\x00\x10", 4) == 0
                                                              : head.compare(0, 4, "\xe0\x7f\x10\x00", 4) == 0);
            const std::size_t at = header - 4;
            const std::uint32_t stored = !tag_ok ? 0
                                         : big  ? byte(at) << 24 | byte(at + 1) << 16 | byte(at + 2) << 8 | byte(at + 3)
                                                : byte(at + 3) << 24 | byte(at + 2) << 16 | byte(at + 1) << 8 | byte(at);
            if (tag_ok && stored == length) h.native_offset = end - length;
        }
    }
    if (!h.has_pixels && !h.float_pixels) {
        // a reader that stops before the Pixel Data: its presence shows in the bytes that follow
        const std::uint64_t at = reader.GetStreamCurrentPosition();
        const std::string tag = source_bytes(source, at, 4);
        h.has_pixels = tag == std::string("\xe0\x7f\x10\x00", 4) || tag == std::string("\x7f\xe0\x00\x10", 4);
        h.float_pixels = tag == std::string("\xe0\x7f\x08\x00", 4) || tag == std::string("\xe0\x7f\x09\x00", 4);
    }
    // A value of another size would be read here one way and by GDCM's decoder another (which
    // asserts on a SamplesPerPixel it does not expect): refused.
    const auto us = [&](const gdcm::Tag& tag, const char* name, unsigned missing) -> unsigned {
        const std::string_view v = raw_value(ds, tag);
        if (v.empty()) return missing;
        if (v.size() != 2) {
            throw Error(Status::bad_format, str_cat(source.label, ": ", name, " (", std::hex, std::setfill('0'), std::setw(4), tag.GetGroup(), ",",
                                                    std::setw(4), tag.GetElement(), std::dec, ") holds ", v.size(), " bytes; expected one US value (2 bytes)"));
        }
        return *us_value(ds, tag);
    };
    h.rows = us(kRows, "Rows", 0);
    h.columns = us(kColumns, "Columns", 0);
    h.bits_allocated = us(kBitsAllocated, "BitsAllocated", 0);
    h.bits_stored = us(kBitsStored, "BitsStored", h.bits_allocated);
    h.high_bit = us(kHighBit, "HighBit", h.bits_stored > 0 ? h.bits_stored - 1 : 0);
    h.representation = us(kPixelRepresentation, "PixelRepresentation", 0);
    h.samples_per_pixel = us(kSamplesPerPixel, "SamplesPerPixel", 1);
    // Where the bytes after the header do not show the Pixel Data tag (a deflated data set), an
    // image's attributes say there is one; GDCM's decoder then reads it.
    if (!h.has_pixels && !h.float_pixels && h.rows > 0 && h.columns > 0 && h.bits_allocated > 0) h.has_pixels = true;
    if (auto n = numbers_value(ds, kNumberOfFrames); n && n->size() == 1) {
        const double f = (*n)[0];
        if (!(f >= 1 && f <= 1e9 && f == std::floor(f))) {
            throw Error(Status::bad_format, str_cat(source.label, ": NumberOfFrames ", text_value(ds, kNumberOfFrames),
                                                    " is not a whole number >= 1"));
        }
        h.frames = static_cast<std::int64_t>(f);
    }
    // Nothing is allocated per frame before the bytes could hold the frames: native frames take
    // their samples' bytes, encapsulated ones at least an 8-byte item header each.
    {
        const std::uint64_t size = source.in_memory ? source.bytes.size() : InputFile(source.path, source.label).size();
        const std::uint64_t frame_bytes = is_native(h.ts) ? std::max<std::uint64_t>(1, std::uint64_t{h.rows} * h.columns * (h.bits_allocated / 8)) : 8;
        if (static_cast<std::uint64_t>(h.frames) > size / frame_bytes + 1) {
            throw Error(Status::truncated_file,
                        str_cat(source.label, ": NumberOfFrames ", h.frames, " of ", h.columns, "x", h.rows, " pixels cannot fit in the file's ",
                                size, " bytes (file cut short, or a wrong NumberOfFrames?)"));
        }
    }
    // GDCM's decoders allocate what Rows x Columns x frames declare: a compressed Pixel Data must
    // be able to hold it. Real images compress a few times; 1024:1 leaves room for near-constant
    // ones and keeps a crafted header from asking for gigabytes out of a few bytes.
    if (!is_native(h.ts) && h.has_pixels) {
        constexpr std::uint64_t kMaxRatio = 1024;
        const std::uint64_t declared = std::uint64_t{h.rows} * h.columns * std::max(1u, h.samples_per_pixel) *
                                       ((h.bits_allocated + 7) / 8) * static_cast<std::uint64_t>(h.frames);
        if (declared > kMaxRatio * std::max<std::uint64_t>(h.layout.pixel_bytes, 1)) {
            throw Error(Status::bad_format,
                        str_cat(source.label, ": ", h.frames, " frame", h.frames == 1 ? "" : "s", " of ", h.columns, "x", h.rows, " pixels (",
                                h.samples_per_pixel, " sample", h.samples_per_pixel == 1 ? "" : "s", ", ", h.bits_allocated, " bits allocated) take ",
                                declared, " bytes but the compressed Pixel Data holds ", h.layout.pixel_bytes,
                                "; expected at most 1024 times its size (a wrong Rows, Columns or NumberOfFrames?)"));
        }
    }
    if (h.ts == gdcm::TransferSyntax::RLELossless && h.has_pixels) {
        const unsigned segments = std::max(1u, h.samples_per_pixel) * ((h.bits_allocated + 7) / 8);
        const auto frames = static_cast<std::uint64_t>(h.frames);
        if (source.in_memory) check_rle(MemoryInput(source.bytes, source.label), h.layout, frames, h.rows, h.columns, segments);
        else check_rle(InputFile(source.path, source.label), h.layout, frames, h.rows, h.columns, segments);
    }
    Geometry top;
    read_geometry(ds, top);
    if (!top.pixel_spacing) {
        if (auto s = numbers_value(ds, kImagerPixelSpacing); s && s->size() == 2)
            top.pixel_spacing = std::array<double, 2>{(*s)[0], (*s)[1]};
    }
    std::vector<gdcm::SmartPointer<gdcm::SequenceOfItems>> keep;
    gdcm::SmartPointer<gdcm::SequenceOfItems> per_frame;
    try {
        // GDCM parses a sequence held as bytes (Implicit VR, UN) only when asked, and may throw
        // plain strings doing so
        if (const gdcm::DataSet* shared = first_item(ds, kSharedGroups, keep)) read_functional_groups(*shared, top);
        if (ds.FindDataElement(kPerFrameGroups)) per_frame = ds.GetDataElement(kPerFrameGroups).GetValueAsSQ();
    } catch (const Error&) {
        throw;
    } catch (...) {
        throw Error(Status::bad_format, source.label + ": GDCM cannot read the functional groups sequences (5200,9229) and (5200,9230)");
    }
    if (per_frame && per_frame->GetNumberOfItems() > 0) {
        if (static_cast<std::int64_t>(per_frame->GetNumberOfItems()) != h.frames) {
            throw Error(Status::bad_format,
                        str_cat(source.label, ": PerFrameFunctionalGroupsSequence has ", per_frame->GetNumberOfItems(),
                                " items but NumberOfFrames is ", h.frames, "; expected one item per frame"));
        }
        h.geometry.reserve(static_cast<std::size_t>(h.frames));
        try {
            for (std::size_t f = 1; f <= per_frame->GetNumberOfItems(); ++f) {
                Geometry g = top;
                read_functional_groups(per_frame->GetItem(f).GetNestedDataSet(), g);
                h.geometry.push_back(g);
            }
        } catch (const Error&) {
            throw;
        } catch (...) {
            throw Error(Status::bad_format, source.label + ": GDCM cannot read the per-frame functional groups sequence (5200,9230)");
        }
    } else if (h.frames == 1) {
        h.geometry.push_back(top);
    } else {
        // a multi-frame file without per-frame positions: the frames cannot be placed
        h.geometry.assign(static_cast<std::size_t>(h.frames), Geometry{std::nullopt, top.orientation, top.pixel_spacing,
                                                                      top.slope, top.intercept});
    }
    return h;
}

// ---- inputs ---------------------------------------------------------------------------------

/// The files a DICOMDIR names (its directory records' ReferencedFileID, relative to its folder).
std::vector<fs::path> dicomdir_files(const fs::path& dicomdir)
{
    quiet_gdcm();
    scan_dicom(InputFile(dicomdir, dicomdir.string()), dictionary_vr);
    gdcm::Reader reader;
    reader.SetFileName(dicomdir.c_str());
    bool ok = false;
    try {
        ok = reader.Read();
    } catch (...) { // GDCM also throws plain strings
        ok = false;
    }
    if (!ok) throw Error(Status::bad_format, dicomdir.string() + ": not a DICOMDIR GDCM can read");
    const gdcm::DataSet& ds = reader.GetFile().GetDataSet();
    std::vector<fs::path> files;
    if (!ds.FindDataElement(kDirectoryRecords)) return files;
    gdcm::SmartPointer<gdcm::SequenceOfItems> records;
    try {
        records = ds.GetDataElement(kDirectoryRecords).GetValueAsSQ();
    } catch (...) {
        throw Error(Status::bad_format, dicomdir.string() + ": GDCM cannot read the DirectoryRecordSequence (0004,1220)");
    }
    if (!records) return files;
    for (std::size_t i = 1; i <= records->GetNumberOfItems(); ++i) {
        const std::string id = text_value(records->GetItem(i).GetNestedDataSet(), kReferencedFileId);
        if (id.empty()) continue;
        fs::path file = dicomdir.parent_path();
        std::size_t start = 0;
        while (start <= id.size()) {
            const std::size_t stop = std::min(id.find('\\', start), id.size());
            const std::string part(trim(std::string_view(id).substr(start, stop - start)));
            if (!part.empty() && part != "." && part != "..") file /= part;
            start = stop + 1;
        }
        std::error_code ec;
        if (!fs::exists(file, ec)) {
            // media are written in upper case; a copy may have been lower-cased
            fs::path lower = dicomdir.parent_path() / lower_ascii(fs::relative(file, dicomdir.parent_path(), ec).string());
            if (fs::exists(lower, ec)) file = lower;
        }
        files.push_back(file);
    }
    std::sort(files.begin(), files.end());
    files.erase(std::unique(files.begin(), files.end()), files.end());
    return files;
}

enum class InputKind { folder, dicomdir, file };

InputKind input_kind(const fs::path& path)
{
    std::error_code ec;
    if (fs::is_directory(path, ec)) return InputKind::folder;
    if (!fs::exists(path, ec)) throw Error(Status::io_error, path.string() + ": cannot open: no such file or folder");
    if (is_dicomdir_name(path)) return InputKind::dicomdir;
    return InputKind::file;
}

/// The headers of every DICOM file of an input.
std::vector<Header> read_headers(const std::vector<Source>& sources)
{
    std::vector<Header> headers;
    headers.reserve(sources.size());
    for (std::size_t i = 0; i < sources.size(); ++i) headers.push_back(read_header(sources[i], i));
    return headers;
}

std::vector<Source> input_sources(const fs::path& path)
{
    std::vector<fs::path> files;
    switch (input_kind(path)) {
    case InputKind::folder:
        files = folder_dicom_files(path);
        if (files.empty()) {
            throw Error(Status::unsupported_format,
                        path.string() + ": no DICOM file in the folder (expected files with the \"DICM\" mark, or named *.dcm)");
        }
        break;
    case InputKind::dicomdir:
        files = dicomdir_files(path);
        if (files.empty()) throw Error(Status::bad_format, path.string() + ": the DICOMDIR names no file");
        for (const fs::path& f : files) {
            std::error_code ec;
            if (!fs::is_regular_file(f, ec)) {
                throw Error(Status::io_error, str_cat(path.string(), ": names ", f.string(), ", which is not there"));
            }
        }
        break;
    case InputKind::file: files = {path}; break;
    }
    std::vector<Source> sources;
    sources.reserve(files.size());
    for (const fs::path& f : files) sources.push_back(Source{f, {}, false, f.string()});
    return sources;
}

/// A single file that names a DICOMDIR in its meta header is read as one.
std::vector<Header> headers_of(const fs::path& path, std::vector<Source>& sources)
{
    sources = input_sources(path);
    std::vector<Header> headers = read_headers(sources);
    if (headers.size() == 1 && headers.front().modality == "DICOMDIR") {
        sources.clear();
        for (const fs::path& f : dicomdir_files(path)) sources.push_back(Source{f, {}, false, f.string()});
        if (sources.empty()) throw Error(Status::bad_format, path.string() + ": the DICOMDIR names no file");
        headers = read_headers(sources);
    }
    return headers;
}

} // namespace cmc33::io::detail::dicom_gdcm

#endif // CMC33_WITH_GDCM
