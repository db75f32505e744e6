#pragma once
/// @file mesh.hpp
/// An indexed triangle mesh: a vertex is shared by every triangle that uses it.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>
#include "cmc33/base_export.hpp"

namespace cmc33 {

namespace detail {
/// Memory for Buffer: large blocks (1 MiB and more) are rounded up to whole 2 MiB pages, 2 MiB
/// aligned and marked for transparent huge pages, so that filling a big mesh takes hundreds of
/// times fewer page faults. Freed blocks of up to 16 MiB (at most four) are kept for the next
/// allocation of their size; blocks from 64 KiB to 1 MiB are rounded up to size classes (at most
/// 1/8 more) and up to eight are kept alike. Blocks past 16 MiB are rounded up to size classes
/// too and up to four are kept, until an allocation past 16 MiB that none fits releases them.
/// @throws Error{too_large} "cannot allocate N bytes for the mesh (out of memory)"
CMC33_BASE_EXPORT void* allocate_buffer(std::size_t bytes);
CMC33_BASE_EXPORT void deallocate_buffer(void* p, std::size_t bytes) noexcept;
/// Frees every kept block: for a caller bound to a memory limit (the slabs of --memory-limit),
/// where blocks kept for sizes that never come again would add up past it.
CMC33_BASE_EXPORT void release_kept_buffers() noexcept;
} // namespace detail

/// Whether Buffer's blocks of 1 MiB and more are advised for transparent huge pages (Linux; on by
/// default): filling a large mesh then takes hundreds of times fewer page faults. On a VM whose
/// memory balloon reports free memory to its host a new huge page costs more than it saves
/// (docs/performance.md, "Memory"); the command line and the Python module turn the advice off
/// there. Applies to blocks allocated after the call; thread-safe.
CMC33_BASE_EXPORT void set_huge_page_advice(bool advise) noexcept;
CMC33_BASE_EXPORT bool huge_page_advice() noexcept;

/// std::allocator, except that resize(n) leaves new elements default-initialised (for float and
/// integers: not written) instead of zeroing them. The extractor sizes a mesh once and writes every
/// element in parallel; zeroing it first would be a second, single-threaded pass over the output.
template <class T> struct DefaultInitAllocator : std::allocator<T> {
    template <class U> struct rebind {
        using other = DefaultInitAllocator<U>;
    };
    DefaultInitAllocator() noexcept = default;
    template <class U> DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
    T* allocate(std::size_t n)
    {
        if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
        return static_cast<T*>(detail::allocate_buffer(n * sizeof(T)));
    }
    void deallocate(T* p, std::size_t n) noexcept { detail::deallocate_buffer(p, n * sizeof(T)); }
    template <class U> void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>)
    {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args> void construct(U* p, Args&&... args)
    {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

/// A vector whose resize() does not zero new elements (see DefaultInitAllocator).
template <class T> using Buffer = std::vector<T, DefaultInitAllocator<T>>;


struct Mesh {
    Buffer<float> positions;        ///< 3 per vertex, world coordinates
    Buffer<float> normals;          ///< empty, or 3 per vertex (unit length)
    Buffer<std::uint32_t> triangles; ///< 3 vertex indices per triangle, counter-clockwise
                                         ///< seen from the side the normal points to

    std::size_t vertex_count() const noexcept { return positions.size() / 3; }
    std::size_t triangle_count() const noexcept { return triangles.size() / 3; }
    bool has_normals() const noexcept { return !normals.empty(); }
};

} // namespace cmc33
