#pragma once
/// @file extract.hpp
/// The isosurface extractor: Marching Cubes 33 with the corrections of Custodio, Etiene, Pesco and
/// Silva 2013 (method `cmc33`), and for comparison the methods that paper compares: Chernyaev's
/// MC33 (`chernyaev`), Lewiner et al.'s (`mc33-lewiner`), the paper's own C-MC33 (`cmc33-paper`)
/// and classic Marching Cubes (`mc`). One code path; the decision policy and the table set are
/// chosen per call.

#include <array>
#include <cstdint>
#include <vector>
#include <functional>
#include <string_view>

#include "cmc33/mesh.hpp"
#include "cmc33/threads.hpp"
#include "cmc33/volume.hpp"
#include "cmc33/core_export.hpp"

namespace cmc33 {

/// The methods of Custodio et al. 2013 (C13). Two table sets (src/tables/mc33_tables.hpp): embedded
/// tubes (cmc33, mc) and Chernyaev's tubes, which lie in a cell face where they cross an ambiguous
/// one, so that two neighbouring tunnels through one face give non-manifold edges (C13 Sec. 5.2;
/// chernyaev, mc33-lewiner, cmc33-paper).
enum class Method {
    cmc33,        ///< default: C13's decisions, embedded tubes: topologically correct, manifold, embedded
    mc33_lewiner, ///< Lewiner et al. 2003: t_alt for cases 6, 7, 12, 13 (C13 Issue III), no joined
                  ///< branch of cases 10 and 12 (Issue IV), 13.5 by condition (iii) (Issue I); Chernyaev's tubes
    mc,           ///< classic Marching Cubes: one triangulation per sign configuration
    chernyaev,    ///< Chernyaev 1995: t_max and his three conditions everywhere, 13.5 included (C13
                  ///< Issue I), Algorithm 2 complete; his tubes (Issue II)
    cmc33_paper,  ///< C13's C-MC33: cmc33's decisions, Chernyaev's tubes, and the grid refinement of
                  ///< C13 Sec. 6.2 wherever two tunnels share an ambiguous face (extract() only)
};

/// "cmc33", "mc33-lewiner", "mc", "chernyaev", "cmc33-paper"
CMC33_CORE_EXPORT std::string_view method_name(Method method) noexcept;
/// @throws Error{invalid_argument} naming the accepted names.
CMC33_CORE_EXPORT Method parse_method(std::string_view name);

/// Subcases of Chernyaev's table, numbered 0..32 in the order
/// 0, 1, 2, 3.1, 3.2, 4.1.1, 4.1.2, 5, 6.1.1, 6.1.2, 6.2, 7.1, 7.2, 7.3, 7.4.1, 7.4.2, 8, 9,
/// 10.1.1, 10.1.2, 10.2, 11, 12.1.1, 12.1.2, 12.2, 12.3, 13.1, 13.2, 13.3, 13.4, 13.5.1, 13.5.2, 14.
inline constexpr int kSubcaseCount = 33;
CMC33_CORE_EXPORT std::string_view subcase_name(int subcase) noexcept;

/// Runs task(0), ..., task(n - 1), possibly at the same time, and returns when all have returned.
/// If tasks throw, it rethrows one of their exceptions after all have ended. The default
/// (an empty Executor) runs them on the calling thread and the process's pool of worker threads,
/// which stay asleep between calls (started on first use; while another call holds the pool, a
/// call starts threads of its own); a caller can run the tasks on its own pool (TBB,
/// vtkSMPTools, a Python executor) instead.
using Executor = std::function<void(int n, const std::function<void(int task)>& task)>;

/// Called with the fraction of the work done, in [0, 1], from one of the tasks' threads (never two
/// calls at once, at most every few milliseconds); return false to stop: extract() then throws
/// Error{cancelled} and returns no mesh.
using Progress = std::function<bool(double fraction)>;

struct ExtractOptions {
    Method method = Method::cmc33;
    bool normals = false; ///< per-vertex normals from the field's gradient (central differences)
    /// thread_count(threads) (cmc33/threads.hpp: 0 is all cores), at most one per sample plane. The
    /// mesh is byte-identical for every thread count.
    int threads = 0;
    Progress progress{};  ///< optional: progress and cancellation
    Executor executor{};  ///< optional: where the `threads` tasks run
};

struct ExtractStats {
    std::array<std::int64_t, kSubcaseCount> cells_per_subcase{}; ///< cells the surface crosses
    std::int64_t refinement_planes = 0; ///< cmc33_paper: sample planes added (C13 Sec. 6.2); else 0
    /// Where the mesh's sample planes start (passes.hpp's numbering), nz + 1 entries each, the last
    /// the totals: plane k's vertices are [plane_first_vertex[k], plane_first_vertex[k + 1]) and cell
    /// layer k's triangles [plane_first_triangle[k], plane_first_triangle[k + 1]). What
    /// check_extracted_mesh() (topology.hpp) needs. Empty when cmc33_paper refined the grid.
    std::vector<std::int64_t> plane_first_vertex, plane_first_triangle;
};

/// Extracts S = {x : f(x) = iso}, f the trilinear interpolant of the samples.///
/// Method cmc33_paper first looks for pairs of neighbouring cells whose (Chernyaev) tubes both lie
/// in the face they share; while there are any, it splits the slab of cells holding each such face
/// by a plane through the face's saddle point (C13 Sec. 6.2, Fig. 11: the interpolant is unchanged,
/// the face's ambiguity is gone) and looks again; then it extracts from the refined grid. Its
/// vertices therefore include points on the added planes, and `stats` counts the refined cells.

///
/// Sign rule: a sample (or face or interior saddle) equal to iso counts as above it.
/// One vertex per crossed grid edge, shared by every cell around that edge; cells whose subcase
/// needs them add interior vertices. Triangles wind counter-clockwise seen from below iso: normals
/// point from the above-iso side to the below-iso side (docs/conventions.md).
///
/// @param grid  at least 2 samples on each axis
/// @throws Error{invalid_argument} if an axis has < 2 samples; Error{non_finite} if iso or a
///         sample is NaN or infinite (the message says how many and where the first is);
///         Error{cancelled} if options.progress returned false
/// Cost: O(cells) time; working memory O(slices); no allocation inside a pass.
/// The composition of the passes of passes.hpp over `threads` ranges of sample planes.
template <class T>
CMC33_CORE_EXPORT Mesh extract(const GridView<T>& grid, double iso, const ExtractOptions& options = {}, ExtractStats* stats = nullptr);
CMC33_CORE_EXPORT Mesh extract(const Volume& volume, double iso, const ExtractOptions& options = {}, ExtractStats* stats = nullptr);

/// How finely 32-bit floats resolve a grid's cells in world space: 1 over the largest distance, in
/// cells along any grid axis, that rounding a world position of the grid's box to float can move it
/// (+inf where no component needs rounding). extract() keeps vertices at least 16 float steps from
/// the samples, within 1/8 of an edge, and so needs kMinFloatStepsPerCell: far from the origin
/// (scanner or map coordinates with fine cells) it refuses the grid with Error{too_large}.
/// Extracting with the origin at 0 and adding it back in double precision keeps such a mesh
/// embedded (cmc33 extract does so; docs/conventions.md).
inline constexpr double kMinFloatStepsPerCell = 128;
CMC33_CORE_EXPORT double float_steps_per_cell(const Index3& dims, const Vec3& spacing, const Vec3& origin,
                                              const Mat3& direction);

} // namespace cmc33
