#pragma once
/// @file io.hpp
/// Reading and writing volumes and meshes. The format follows the file name's extension.
///
/// Volumes: NRRD (.nrrd attached, .nhdr detached; raw or gzip), MetaImage (.mhd/.mha), VTK legacy
/// STRUCTURED_POINTS (.vtk, binary or ASCII), and headerless raw (any other name, with RawOptions).
/// Meshes: PLY (binary little-endian by default, or ASCII), OBJ, binary STL, OFF; written only:
/// glTF 2.0 (.glb, .gltf), VTK XML PolyData (.vtp), GIfTI (.gii).
///
/// Every reader checks every size it is told against what the file holds before allocating, and
/// throws `Error` with a one-line message that names the file, what is wrong and what was expected.
/// Fewer or more data than a header declares is an error; docs/formats.md gives the whole policy
/// (trailing bytes, final newlines, text cut inside a number). Each reader is fuzzed (fuzz/).
/// Writers write a temporary file next to the target and rename it, so a failed write never leaves
/// a half-written file behind.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"
#include "cmc33/io_export.hpp"

namespace cmc33::io {

enum class Endian { little, big };

/// What a headerless raw file cannot say about itself.
struct RawOptions {
    Index3 dims{0, 0, 0};
    ScalarType type = ScalarType::u8;
    Vec3 spacing{1, 1, 1};
    Endian endian = Endian::little;
    std::uint64_t header_bytes = 0; ///< bytes to skip at the start
};

/// The choices a file leaves to its reader: which of several volumes it holds to read, and the frame
/// of a format that has none. Each field matters to some formats and is ignored by the others.
struct ReadOptions {
    /// 4-D files (NIfTI dim[4] > 1): the frame to read, from 0, as nibabel's img.dataobj[..., N].
    /// Required when the file holds several frames; a 3-D file has frame 0 only.
    std::optional<std::int64_t> frame;
    /// VTK XML ImageData (.vti): the point-data array to read when there are several (default:
    /// the active Scalars, else the only array).
    std::string array;
    /// DICOM: the SeriesInstanceUID to read when a folder holds several series.
    std::string series;
    /// Formats that give no frame (.npy): the distance between samples along x, y, z and the
    /// position of the first sample (defaults 1 and 0). Refused for formats that give their own.
    std::optional<Vec3> spacing, origin;
};

/// Parses "int8|uint8|int16|uint16|int32|uint32|float|double" (also "char", "uchar", "short",
/// "ushort", "int", "uint", "float32", "float64"). @throws Error{invalid_argument}.
CMC33_IO_EXPORT ScalarType parse_type(const std::string& name);

/// Reads a volume; `raw` is required for headerless files and ignored otherwise.
/// Samples are converted to the machine's byte order.
/// @throws Error (io_error, truncated_file, bad_format, unsupported_format, too_large)
CMC33_IO_EXPORT Volume read_volume(const std::filesystem::path& path, const std::optional<RawOptions>& raw = std::nullopt,
                                   const ReadOptions& options = {});

/// One DICOM series of an input (a folder, a DICOMDIR or a file), as `cmc33 info` lists them.
struct DicomSeries {
    std::string uid;         ///< SeriesInstanceUID
    std::string description; ///< SeriesDescription (may be empty)
    std::string modality;    ///< Modality (CT, MR, ...; may be empty)
    Index3 dims{0, 0, 0};    ///< columns, rows, slices (frames)
    Vec3 spacing{0, 0, 0};   ///< between columns, between rows, between slices (0 when it cannot be read)
    std::size_t files = 0;   ///< the files that hold it
    std::string problem;     ///< why the series cannot be read as a volume (empty when it can)
};

/// The DICOM series `path` holds (a folder of slice files, a DICOMDIR or one file), from the
/// files' headers only, in the order of their UIDs. @throws Error for a missing input or one
/// without a DICOM image, or when this build has no DICOM reader.
CMC33_IO_EXPORT std::vector<DicomSeries> dicom_series(const std::filesystem::path& path);

/// Inputs told by their content, which read_volume() reads without RawOptions: DICOM (a folder
/// of DICOM files, a DICOMDIR, a file with the "DICM" mark) and TIFF (a file with the TIFF mark,
/// a folder of .tif/.tiff slices). Never throw.
CMC33_IO_EXPORT bool is_dicom_input(const std::filesystem::path& path);
CMC33_IO_EXPORT bool is_tiff_input(const std::filesystem::path& path);

/// Moves the volume's frame into the anatomical world space `space`: "ras" (x to the right, y
/// anterior, z superior: NIfTI's, nibabel's affine) or "lps" (DICOM's, NRRD's usual), or a NRRD
/// space name. The world axes whose direction differs from the volume's space() are negated (origin
/// and direction rows); space() names the new space. @throws Error{invalid_argument} when the
/// volume names no space (e.g. .npy, NIfTI without sform or qform) or one that is not anatomical.
CMC33_IO_EXPORT void convert_space(Volume& volume, std::string_view space);

/// Writes a volume: .nrrd (attached, raw), .nhdr (+ .raw beside it), .mhd (+ .raw), .mha,
/// .vtk (binary, big-endian), .raw (headerless, machine order). @throws Error.
CMC33_IO_EXPORT void write_volume(const Volume& volume, const std::filesystem::path& path);

/// A named array written beside a mesh, one tuple of `components` values per vertex or per
/// triangle (VTK XML PolyData point or cell data; PLY face properties). Not owned: the values must
/// outlive the write.
struct MeshArray {
    std::string name;
    /// Float32, Int32 or Int64 (in PLY, whose integers are 32-bit: int or uint when every value
    /// fits one of them, else refused)
    std::variant<std::span<const float>, std::span<const std::int32_t>, std::span<const std::int64_t>> values;
    int components = 1;
};

struct MeshWriteOptions {
    bool ascii = false; ///< PLY only: ASCII instead of binary little-endian
    /// Set: the mesh's positions are relative to this point, and are written in double precision
    /// as offset + position (PLY `property double`, shortest round-trip text in OBJ and OFF, VTP
    /// Float64 points, GIfTI NIFTI_TYPE_FLOAT64, a glTF node translation; STL, 32-bit floats only,
    /// refuses it). For meshes extracted with the volume's origin moved to 0, far from which floats
    /// cannot keep them embedded (float_steps_per_cell()).
    std::optional<Vec3> offset{};
    /// The world space of the positions as Volume::space() names it ("left-posterior-superior",
    /// "RAS", ...; empty: not known). glTF states it in `extras`; GIfTI writes RAS+ coordinates,
    /// converting from another anatomical space (docs/formats.md).
    std::string space{};
    std::vector<MeshArray> vertex_arrays{}; ///< .vtp point data (e.g. the values at the vertices)
    /// .vtp cell data, .ply face properties (e.g. a label per triangle)
    std::vector<MeshArray> triangle_arrays{};
    /// Optional: called once all bytes are written, before they replace the file (for .gltf,
    /// before its .bin does). An exception from it leaves every file as it was and propagates:
    /// a caller can write while it still computes something the file must wait for.
    std::function<void()> before_commit{};
};

/// Writes .ply, .obj, .stl (binary), .off, .glb, .gltf (+ a .bin of the same stem beside it),
/// .vtp (VTK XML PolyData, zlib-compressed appended data) or .gii (GIfTI surface). Normals are
/// written where the format carries them (PLY, OBJ, glTF, VTP, GIfTI).
/// @throws Error{unsupported_format} for another extension, Error{io_error}.
CMC33_IO_EXPORT void write_mesh(const Mesh& mesh, const std::filesystem::path& path, const MeshWriteOptions& options = {});

/// One mesh of a scene (write_scene()): its name and base colour (linear RGBA in [0, 1]).
struct ScenePart {
    const Mesh* mesh = nullptr; ///< not owned
    std::string name{};
    std::optional<std::array<float, 4>> colour{};
};

/// Writes several meshes as one glTF 2.0 scene, .glb or .gltf (+ a .bin of the same stem beside
/// it): a node and a mesh per part, named, with a material of its colour (a label map's surfaces).
/// @throws Error{unsupported_format} for another extension, Error{invalid_argument} for a part
/// without a mesh or a colour outside [0, 1], Error{io_error}.
CMC33_IO_EXPORT void write_scene(const std::vector<ScenePart>& parts, const std::filesystem::path& path,
                                 const MeshWriteOptions& options = {});

/// Reads .ply (ASCII or binary, either endian), .obj, .stl (binary or ASCII) or .off. Polygons
/// with more than three vertices are fanned. STL has no indices: exactly coincident vertices are
/// welded. @throws Error.
CMC33_IO_EXPORT Mesh read_mesh(const std::filesystem::path& path);

/// A label's name and display colour (a label map's, for the meshes of its labels).
struct LabelName {
    std::int64_t value = 0;
    std::string name{};                          ///< may be empty: a colour without a name
    std::optional<std::array<float, 3>> colour{}; ///< sRGB, each channel from 0 to 1
};

/// The segments a 3D Slicer segmentation's NRRD header names (.seg.nrrd: SegmentN_Name,
/// SegmentN_Color, SegmentN_LabelValue, SegmentN_Layer), those of layer 0 with a label value; none
/// for a file that is not NRRD (or not a file) or has no segments. Reads the header only.
/// @throws Error for a segment field that is not what Slicer writes, or two segments of one value.
CMC33_IO_EXPORT std::vector<LabelName> read_segment_names(const std::filesystem::path& volume);
/// read_segment_names() of a header in memory; `label` names it in messages.
CMC33_IO_EXPORT std::vector<LabelName> parse_segment_names(std::string_view header, const std::string& label);

/// A colour table: lines "value name [R G B [A]]" (3D Slicer's .ctbl/.txt, FreeSurfer's LUT;
/// channels 0-255, the name one word or in double quotes) or ITK-SNAP's label descriptions
/// "value R G B A visible mesh \"name\"" (A from 0 to 1); blank lines and "#" comments skipped.
/// @throws Error naming the line that is neither, a value named twice, or a table without labels.
CMC33_IO_EXPORT std::vector<LabelName> read_colour_table(const std::filesystem::path& table);
/// read_colour_table() of text in memory; `label` names it in messages.
CMC33_IO_EXPORT std::vector<LabelName> parse_colour_table(std::string_view text, const std::string& label);

/// A volume format, for bytes that have no file name to tell it.
enum class VolumeFormat {
    nrrd,      ///< attached header (the samples follow it) or detached ("data file: NAME")
    metaimage, ///< .mha (ElementDataFile = LOCAL) or .mhd (ElementDataFile = NAME)
    vtk,       ///< VTK legacy STRUCTURED_POINTS
    raw,       ///< headerless samples described by RawOptions
    nifti,     ///< NIfTI-1 or NIfTI-2: .nii (gzip-compressed or not), or a .hdr whose .img is a data file
    npy,       ///< NumPy .npy, versions 1.0, 2.0, 3.0
    vti,       ///< VTK XML ImageData
    dicom,     ///< one DICOM file: a multi-frame image (Enhanced CT/MR and the like)
    tiff,      ///< one TIFF file: its pages are the z slices (ImageJ hyperstacks, OME-TIFF)
};

/// The data files of a detached header, held in memory: called with the name as the header writes
/// it ("data file:" in NRRD, ElementDataFile in MetaImage), returns that file's bytes, or nullopt
/// if there is no such file. The bytes must stay valid until the read returns.
using MemoryFiles = std::function<std::optional<std::string_view>(std::string_view name)>;

/// Reads a volume from bytes in memory, exactly as read_volume() reads a file of that format
/// (the same parser and the same checks; read_volume() calls the same code). `label` stands for
/// the file's name at the start of every message. `raw` is required for VolumeFormat::raw and
/// ignored otherwise; `data_files` serves the data files of detached headers (none if empty).
/// @throws Error, as read_volume(); never another exception type, whatever the bytes.
///
///     const io::MemoryFiles files = [&](std::string_view name) {
///         return name == "ct.raw" ? std::optional<std::string_view>(raw_bytes) : std::nullopt;
///     };
///     Volume v = io::read_volume_from_memory(nhdr_text, io::VolumeFormat::nrrd, "ct.nhdr",
///                                            std::nullopt, files);
CMC33_IO_EXPORT Volume read_volume_from_memory(std::string_view bytes, VolumeFormat format, const std::string& label,
                               const std::optional<RawOptions>& raw = std::nullopt,
                               const MemoryFiles& data_files = {}, const ReadOptions& options = {});

/// A mesh format, for bytes that have no file name to tell it.
enum class MeshFormat { ply, obj, stl, off };

/// Reads a mesh from bytes in memory, exactly as read_mesh() reads a file of that format (which
/// calls this). `label` stands for the file's name at the start of every message.
/// @throws Error, as read_mesh(); never another exception type, whatever the bytes.
CMC33_IO_EXPORT Mesh read_mesh_from_memory(std::string_view bytes, MeshFormat format, const std::string& label);

/// True for names whose extension read_volume() knows without RawOptions.
CMC33_IO_EXPORT bool has_volume_header(const std::filesystem::path& path);

/// Every file that reading the volume `path` may open, found without reading samples: `path`,
/// then the data files its header names (NRRD "data file:", MetaImage ElementDataFile; a single
/// name, a LIST, or a numbered pattern's first 65536 names), relative to the header's folder as
/// read_volume() resolves them. Lists the forms read_volume() refuses too: for the rule that a
/// command never writes over a file it reads. Only `path` when its header cannot be read or names
/// no other file. Never throws Error.
CMC33_IO_EXPORT std::vector<std::filesystem::path> volume_files(const std::filesystem::path& path);

} // namespace cmc33::io
