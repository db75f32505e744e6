#pragma once
// Internal: extraction of a range of a volume's sample planes that never holds the whole volume
// nor the whole mesh, for `cmc33 extract --memory-limit` (one process, the whole range, slab by
// slab through a bounded buffer) and cmc33-mpi (one range per rank). Not part of the installed
// library: the two front ends link it.
//
// A range [K0, K1) is cut into slabs of planes that fit the memory budget. Two passes:
//   count  every slab is read (planes stream through two buffers, the next slab read while the
//          current one is counted) and counted with count() of passes.hpp: the range's vertex and
//          triangle numbers, subcases, the bound on |sample| that scales normals, non-finite
//          samples;
//   emit   given the range's first ids (the ranges before it) and the bound of the whole volume,
//          every slab is read again (or kept, when the range is one slab) and emitted; its
//          vertices and triangles go to the binary PLY at their offsets (MeshWriter), and the
//          slab's topology (SeamTopology) and geometry are summed up with the cell layers on
//          either side of it, which the slab emits itself from two extra planes of its buffer:
//          no slab needs another's mesh.
// Every byte written is the byte `cmc33 extract` writes at that offset, for every split.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/volume.hpp"
#include "plane_reader.hpp"
#include "seam_topology.hpp"

namespace cmc33::slabs {

/// Where each part of a binary PLY goes (mesh_ply.cpp's layout).
struct PlyLayout {
    std::uint64_t header_bytes = 0;
    std::uint64_t vertices = 0, triangles = 0;
    std::size_t vertex_bytes = 12; ///< 12, or 24 with normals
    PlyLayout() = default;
    PlyLayout(std::uint64_t vertex_count, std::uint64_t triangle_count, bool normals);
    std::string header() const;
    std::uint64_t vertex_offset(std::int64_t v) const { return header_bytes + static_cast<std::uint64_t>(v) * vertex_bytes; }
    std::uint64_t face_offset(std::int64_t t) const;
    std::uint64_t file_bytes() const { return face_offset(static_cast<std::int64_t>(triangles)); }
    bool normals() const { return vertex_bytes == 24; }
};

/// Where a range's records are written: a positional file, or an MPI file.
class ByteSink {
public:
    virtual ~ByteSink() = default;
    virtual void write_at(std::uint64_t offset, std::span<const std::byte> bytes) = 0;
};

/// The memory budget of a range's run.
struct SlabOptions {
    ExtractOptions extract;        ///< method, normals, threads (progress and executor unused)
    std::uint64_t memory_limit = 0; ///< bytes for samples, counts and mesh; 0: one slab, no limit
    std::int64_t max_slab_planes = 0; ///< at most this many planes per slab (0: as the budget allows; tests)
    bool analyse = true;           ///< topology and geometry (false: --no-topology)
    /// Called with the fraction of this range's work done (both passes), from the calling thread.
    std::function<void(double)> progress;
};

/// Bytes of output staged before a write (1/32 of the memory limit, 64 KiB to 16 MiB): each
/// write is a whole piece, except the last of the vertex records and of the face records, so
/// the number of writes is known in advance (MPI's collective writes need it).
std::size_t piece_bytes(std::uint64_t memory_limit);

/// The number of write_at calls emit() makes for a range of this many vertices and triangles.
std::int64_t write_count(std::int64_t vertices, std::int64_t triangles, bool normals, std::size_t piece);

/// What the count pass found.
struct RangeTotals {
    std::int64_t vertices = 0, triangles = 0;
    double sample_bound = 0;
    ExtractStats stats{};
    std::int64_t non_finite = 0;     ///< NaN or infinite samples among the range's own planes
    Index3 first_non_finite{-1, -1, -1};
    std::int64_t slabs = 0;
    std::int64_t planes_read = 0;    ///< planes read from the file (each once per pass, halos included)
    double wait_seconds = 0;         ///< waiting for planes (reading that the counting did not hide)
    double count_seconds = 0;        ///< counting
};

/// The geometric checks of mesh_geometry() for the triangles and vertices a range owns, each
/// slab with the cell layers on either side of it (triangles of cells two or more layers apart
/// cannot meet unless the frame's spacing is below the floats' resolution of its coordinates).
struct GeometryPart {
    std::int64_t positions = 0;           ///< own used vertices with no twin of a smaller id
    std::int64_t coincident_vertices = 0; ///< own used vertices with a twin
    std::int64_t zero_area_triangles = 0;
    std::int64_t intersecting_pairs = 0;  ///< pairs with at least one own triangle (the other own or below)
    std::vector<std::array<std::int64_t, 2>> examples; ///< global triangle ids, smallest first, at most kExamples
    static constexpr std::size_t kExamples = 8;
    /// Adds `other` (a range elsewhere in the mesh).
    void add(const GeometryPart& other);
};

/// What the emit pass found.
struct RangeResult {
    detail::SeamTopology topology;
    GeometryPart geometry;
    std::int64_t planes_read = 0; ///< planes read from the file (none when the count pass kept them)
    double wait_seconds = 0;      ///< waiting for planes
    double emit_seconds = 0;      ///< counting again and emitting
    double write_seconds = 0;     ///< staging records and writing them to the sink
    double analyse_seconds = 0;   ///< the layers around each slab, its topology and geometry
};

/// MeshGeometry of a whole mesh from its parts and its topology (welded = topology when no two
/// vertices coincide; otherwise the welded topology is not computed: `welded_known` false).
MeshGeometry finish_geometry(const GeometryPart& whole, const MeshTopology& topology, bool& welded_known);

/// One range of planes [k0, k1) of the volume `reader` reads.
class RangeRun {
public:
    /// @throws Error{too_large} if one plane (with the four around it) does not fit the budget
    RangeRun(io::detail::PlaneReader& reader, double iso, SlabOptions options, std::int64_t k0, std::int64_t k1);
    ~RangeRun();
    RangeRun(const RangeRun&) = delete;
    RangeRun& operator=(const RangeRun&) = delete;

    /// The count pass. @throws Error as count() and the reader (non-finite samples are counted,
    /// not thrown)
    RangeTotals count();
    /// The emit pass: the range's vertices start at global id `first_vertex`, its triangles at
    /// `first_triangle`; `sample_bound` is the largest bound of all ranges; records go to `sink`
    /// (nullable) at the offsets of `layout` (the whole mesh's), in write_count() calls.
    RangeResult emit(std::int64_t first_vertex, std::int64_t first_triangle, double sample_bound, const PlyLayout& layout,
                     ByteSink* sink);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The planes [k0, k1) of rank `rank` of `ranks`: equal shares of the volume's nz planes.
std::array<std::int64_t, 2> rank_planes(std::int64_t nz, int rank, int ranks);

/// Parses "256M", "2G", "512k", "1000000" (bytes; k, M, G, T are powers of 1024, an optional
/// trailing B or iB). @throws Error{invalid_argument} naming `text`
std::uint64_t parse_size(const std::string& text);

/// "No NaN or infinity" message of extract(), for `count` non-finite samples, the first at `first`.
std::string non_finite_message(std::int64_t count, const Index3& first);

} // namespace cmc33::slabs
