// GIfTI surfaces (.gii), after "GIFTI Surface Data Format Version 1.0" (the GIfTI specification):
// a DataArray of intent NIFTI_INTENT_POINTSET (n x 3 coordinates), one of NIFTI_INTENT_TRIANGLE
// (m x 3 INT32 vertex indices) and, when the mesh has normals, one of NIFTI_INTENT_VECTOR (n x 3).
// Data are GZipBase64Binary: the little-endian values compressed as a zlib stream, then base64.
//
// Space: GIfTI surfaces are in RAS+ millimetres by convention (the coordinates of the NIfTI volume
// they were made from; FreeSurfer, Connectome Workbench), and the pointset's
// CoordinateSystemTransformMatrix names the space with NIfTI's xform codes (nifti1.h). A mesh in
// another anatomical space (LPS+ from NRRD or DICOM) is written in RAS+: every axis whose
// direction differs is negated. Negating two axes (LPS to RAS) is a rotation, so triangles keep
// their winding; negating one or three is a mirror, which would turn the surface inside out, so
// then each triangle's winding is reversed too and the outward side stays outward. A mesh whose
// space is unknown or not anatomical is written as it is, its space NIFTI_XFORM_UNKNOWN.

#include <array>
#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "cmc33/version.hpp"
#include "mesh_formats.hpp"
#include "volume_formats.hpp"

namespace cmc33::io::detail {
namespace {

/// +1 or -1 per axis: what takes the mesh's space to RAS+; empty when the space is not known
/// or not anatomical.
std::optional<std::array<int, 3>> signs_to_ras(const std::string& space)
{
    if (space.empty()) return std::nullopt;
    Vec3 origin{1, 1, 1};
    Mat3 direction{};
    std::string name = space;
    try {
        convert_space(origin, direction, name, "ras", "mesh");
    } catch (const Error&) {
        return std::nullopt; // a space that is not anatomical ("scanner-xyz", "3D-right-handed", ...)
    }
    return std::array<int, 3>{origin[0] < 0 ? -1 : 1, origin[1] < 0 ? -1 : 1, origin[2] < 0 ? -1 : 1};
}

void metadata(std::string& xml, std::string_view name, std::string_view value)
{
    xml += "<MD><Name>" + xml_escape(name) + "</Name><Value>" + xml_escape(value) + "</Value></MD>\n";
}

void data_array(std::string& xml, const char* intent, const char* type, std::size_t rows, const std::string& bytes,
                const char* space)
{
    xml += std::string("<DataArray Intent=\"") + intent + "\" DataType=\"" + type +
           "\" ArrayIndexingOrder=\"RowMajorOrder\" Dimensionality=\"2\" Dim0=\"" + std::to_string(rows) +
           "\" Dim1=\"3\" Encoding=\"GZipBase64Binary\" Endian=\"LittleEndian\" ExternalFileName=\"\" "
           "ExternalFileOffset=\"\">\n<MetaData/>\n";
    if (space) {
        // The coordinates are already in the named space: an identity transform to itself. One
        // row per line, as GIfTI files are written (nibabel reads the matrix line by line).
        xml += std::string("<CoordinateSystemTransformMatrix>\n<DataSpace>") + space + "</DataSpace>\n<TransformedSpace>" +
               space + "</TransformedSpace>\n<MatrixData>\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n</MatrixData>\n"
                       "</CoordinateSystemTransformMatrix>\n";
    }
    xml += "<Data>";
    const std::string packed = zlib_compress(bytes.data(), bytes.size(), 1); // the fastest level, as .vtp
    append_base64(xml, packed.data(), packed.size());
    xml += "</Data>\n</DataArray>\n";
}

} // namespace

void write_gifti(const Mesh& mesh, std::ostream& out, const MeshWriteOptions& options, const std::string& name)
{
    const std::size_t n = mesh.vertex_count();
    const std::size_t m = mesh.triangle_count();
    if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
        throw Error(Status::too_large, concat(name, ": GIfTI triangles hold INT32 vertex indices: at most 2147483647 "
                                                    "vertices, not ",
                                              n, "; write .ply or .vtp"));
    }
    const std::optional<std::array<int, 3>> signs = signs_to_ras(options.space);
    const std::array<int, 3> s = signs.value_or(std::array<int, 3>{1, 1, 1});
    const bool mirror = s[0] * s[1] * s[2] < 0;

    std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                      "<!DOCTYPE GIFTI SYSTEM \"http://www.nitrc.org/frs/download.php/115/gifti.dtd\">\n";
    xml += "<GIFTI Version=\"1.0\" NumberOfDataArrays=\"" + std::to_string(mesh.has_normals() ? 3 : 2) + "\">\n";
    xml += "<MetaData>\n";
    metadata(xml, "generator", "cmc33 " CMC33_VERSION_STRING);
    metadata(xml, "cmc33_source_space", options.space.empty() ? "unknown" : options.space);
    if (signs) {
        std::string how;
        for (std::size_t k = 0; k < 3; ++k) {
            if (s[k] < 0) how += how.empty() ? std::string(1, "xyz"[k]) : std::string(" and ") + "xyz"[k];
        }
        metadata(xml, "cmc33_space",
                 how.empty() ? "RAS+ as extracted"
                             : "RAS+: " + how + " negated from the source space" +
                                   (mirror ? ", the winding of each triangle reversed" : ""));
    } else {
        metadata(xml, "cmc33_space", "the source's world coordinates as they are (not a known anatomical space)");
    }
    xml += "</MetaData>\n<LabelTable/>\n";
    const char* space = signs ? "NIFTI_XFORM_SCANNER_ANAT" : "NIFTI_XFORM_UNKNOWN";

    // Coordinates: FLOAT32, or FLOAT64 (offset + position in double) for a mesh made at the origin.
    std::string bytes;
    const float* p = mesh.positions.data();
    if (options.offset) {
        bytes.resize(24 * n);
        for (std::size_t i = 0; i < 3 * n; ++i) {
            const double v = s[i % 3] * ((*options.offset)[i % 3] + static_cast<double>(p[i]));
            store_le(bytes.data() + 8 * i, std::bit_cast<std::uint64_t>(v));
        }
    } else {
        bytes.resize(12 * n);
        for (std::size_t i = 0; i < 3 * n; ++i) store_f32_le(bytes.data() + 4 * i, s[i % 3] < 0 ? -p[i] : p[i]);
    }
    data_array(xml, "NIFTI_INTENT_POINTSET", options.offset ? "NIFTI_TYPE_FLOAT64" : "NIFTI_TYPE_FLOAT32", n, bytes,
               space);

    bytes.assign(12 * m, '\0');
    const std::uint32_t* t = mesh.triangles.data();
    for (std::size_t f = 0; f < m; ++f) {
        // a mirror reverses orientation: swapping two corners restores it
        const std::uint32_t b = mirror ? t[3 * f + 2] : t[3 * f + 1];
        const std::uint32_t c = mirror ? t[3 * f + 1] : t[3 * f + 2];
        store_le(bytes.data() + 12 * f, t[3 * f]);
        store_le(bytes.data() + 12 * f + 4, b);
        store_le(bytes.data() + 12 * f + 8, c);
    }
    data_array(xml, "NIFTI_INTENT_TRIANGLE", "NIFTI_TYPE_INT32", m, bytes, nullptr);

    if (mesh.has_normals()) {
        bytes.resize(12 * n);
        const float* v = mesh.normals.data();
        for (std::size_t i = 0; i < 3 * n; ++i) store_f32_le(bytes.data() + 4 * i, s[i % 3] < 0 ? -v[i] : v[i]);
        data_array(xml, "NIFTI_INTENT_VECTOR", "NIFTI_TYPE_FLOAT32", n, bytes, nullptr);
    }
    std::string().swap(bytes);
    xml += "</GIFTI>\n";
    out.write(xml.data(), static_cast<std::streamsize>(xml.size()));
}

} // namespace cmc33::io::detail
