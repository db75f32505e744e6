// Memory for cmc33::Buffer (src/base/include/cmc33/mesh.hpp). A mesh of millions of triangles is written
// once, in parallel; with 4 KiB pages most of that time goes to page faults. Blocks of 1 MiB and
// more are rounded up to whole 2 MiB pages, aligned to 2 MiB and advised for transparent huge
// pages (Linux, when THP is in "madvise" or "always" mode; elsewhere the advice is ignored and
// they are plain pages, of which only the ones written count), at most 2 MiB more per block.
// Freed blocks of up to 16 MiB are kept, up to four, for the next allocation of the same size:
// repeated extractions (an isovalue sweep, `--repeat`, a Python loop) then write memory that is
// already mapped, as glibc's heap would for blocks below its mmap threshold.
// Larger blocks (a mesh of about 1.4 M vertices and more) are rounded up to a size class as
// medium ones are, and up to four are kept too; an allocation that none of them fits releases
// them all first, so that memory is held only for a next mesh of about the same size and never
// beside a mesh of another: the peak stays that of one mesh, and what stays mapped after a mesh
// is freed is at most that mesh's arrays.
// The advice is an option (set_huge_page_advice): on a VM whose balloon reports free memory a new
// huge page is the dearest memory to write first, and the programs that know where they run turn
// it off there.
// Blocks from 64 KiB to 1 MiB are glibc's too, but above its mmap threshold it maps them afresh
// for each allocation, a fault per page written: they are rounded up to a size class (the next
// eighth of their power of two, so that meshes of nearly the same size share one) and up to
// eight are kept the same way. The measurements behind each rule: docs/performance.md, "Memory".
// A failed allocation says how many bytes it wanted: a mesh too large for memory (or for
// `ulimit -v`) is reported as such, and the command line names the file it came from.

#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <new>
#include <string>
#include <utility>

#include "cmc33/error.hpp"
#include "cmc33/mesh.hpp"
#include "portability.hpp"

namespace cmc33::detail {

namespace {
constexpr std::size_t kLarge = kHugePageBytes / 2;
constexpr std::size_t kMedium = std::size_t{64} << 10;

[[noreturn]] void out_of_memory(std::size_t bytes)
{
    throw Error(Status::too_large, "cannot allocate " + std::to_string(bytes) + " bytes for the mesh (out of memory)");
}

/// Freed blocks kept for reuse by size: at most kSlots blocks of at most kLargest bytes each.
template <std::size_t kSlots, std::size_t kLargest> class BlockCache {
public:
    static BlockCache& instance()
    {
        static BlockCache& cache = *new BlockCache; // never destroyed: Buffers may outlive statics
        return cache;
    }
    /// A kept block of exactly `bytes`, or nullptr.
    void* take(std::size_t bytes) noexcept
    {
        const std::lock_guard lock(mutex_);
        for (Block& b : blocks_) {
            if (b.p != nullptr && b.bytes == bytes) return std::exchange(b.p, nullptr);
        }
        return nullptr;
    }
    /// A kept block of exactly `bytes`; else none, having released every kept block p with
    /// release(p).
    template <class Release> void* take_or_release_all(std::size_t bytes, const Release& release) noexcept
    {
        const std::lock_guard lock(mutex_);
        for (Block& b : blocks_) {
            if (b.p != nullptr && b.bytes == bytes) return std::exchange(b.p, nullptr);
        }
        for (Block& b : blocks_) {
            if (b.p != nullptr) release(std::exchange(b.p, nullptr));
        }
        return nullptr;
    }
    /// Releases every kept block p with release(p).
    template <class Release> void release_all(const Release& release) noexcept
    {
        const std::lock_guard lock(mutex_);
        for (Block& b : blocks_) {
            if (b.p != nullptr) release(std::exchange(b.p, nullptr));
        }
    }
    /// Keeps p (of `bytes`) if it is small enough and a slot is free; false: the caller frees it.
    bool keep(void* p, std::size_t bytes) noexcept
    {
        if (bytes > kLargest) return false;
        const std::lock_guard lock(mutex_);
        for (Block& b : blocks_) {
            if (b.p == nullptr) {
                b = {p, bytes};
                return true;
            }
        }
        return false;
    }

private:
    struct Block {
        void* p = nullptr;
        std::size_t bytes = 0;
    };
    std::mutex mutex_;
    std::array<Block, kSlots> blocks_{};
};
constexpr std::size_t kHuge = std::size_t{16} << 20;
using LargeBlocks = BlockCache<4, kHuge>;
using MediumBlocks = BlockCache<8, kLarge>;
using HugeBlocks = BlockCache<4, std::numeric_limits<std::size_t>::max()>;

/// `bytes` rounded up to whole huge pages; 0 when that overflows.
std::size_t whole_pages(std::size_t bytes) noexcept
{
    const std::size_t whole = bytes + (kHugePageBytes - 1 - (bytes - 1) % kHugePageBytes);
    return whole < bytes ? 0 : whole;
}

/// The size class of a medium block of `bytes` (kMedium <= bytes < kLarge) or of one of more
/// than kHuge bytes: rounded up to the next eighth of its power of two (at most 1/8 more), so
/// that meshes of nearly the same size (an isovalue sweep) share a class; past kHuge that is
/// whole huge pages (a step of at least 2 MiB). 0 when that overflows.
std::size_t size_class(std::size_t bytes) noexcept
{
    const std::size_t step = std::bit_floor(bytes) / 8;
    return bytes > std::numeric_limits<std::size_t>::max() - (step - 1) ? 0 : (bytes + step - 1) / step * step;
}

std::atomic<bool> advise_huge_blocks{true}; // set_huge_page_advice

/// A new block of `whole` bytes (whole huge pages, as allocated for a request of `bytes`),
/// 2 MiB aligned, and advised for huge pages where advise_huge_blocks().
void* huge_page_block(std::size_t whole, std::size_t bytes)
{
    if (whole == 0) out_of_memory(bytes);
    void* p = aligned_allocate(kHugePageBytes, whole);
    if (p == nullptr) out_of_memory(bytes);
    if (advise_huge_blocks.load(std::memory_order_relaxed)) advise_huge_pages(p, whole);
    return p;
}
} // namespace

void* allocate_buffer(std::size_t bytes)
{
    if (bytes < kMedium) {
        void* small = ::operator new(bytes, std::nothrow);
        if (small == nullptr) out_of_memory(bytes);
        return small;
    }
    if (bytes < kLarge) {
        // glibc maps blocks this size afresh (its mmap threshold): every page written faults
        const std::size_t size = size_class(bytes);
        if (void* kept = MediumBlocks::instance().take(size)) return kept;
        void* p = ::operator new(size, std::nothrow);
        if (p == nullptr) out_of_memory(bytes);
        return p;
    }
    if (bytes > kHuge) {
        const std::size_t size = size_class(bytes);
        const auto release = [](void* p) noexcept { aligned_free(p); };
        if (void* kept = size == 0 ? nullptr : HugeBlocks::instance().take_or_release_all(size, release)) return kept;
        return huge_page_block(size, bytes);
    }
    // whole huge pages: the last one's tail, in 4 KiB pages, took a fault per page written
    const std::size_t whole = whole_pages(bytes);
    if (void* kept = whole == 0 ? nullptr : LargeBlocks::instance().take(whole)) return kept;
    return huge_page_block(whole, bytes);
}

void deallocate_buffer(void* p, std::size_t bytes) noexcept
{
    if (bytes < kMedium) {
        ::operator delete(p);
    } else if (bytes < kLarge) {
        if (p != nullptr && !MediumBlocks::instance().keep(p, size_class(bytes))) ::operator delete(p);
    } else if (bytes > kHuge) {
        if (p != nullptr && !HugeBlocks::instance().keep(p, size_class(bytes))) aligned_free(p);
    } else if (p != nullptr && !LargeBlocks::instance().keep(p, whole_pages(bytes))) {
        aligned_free(p);
    }
}

void release_kept_buffers() noexcept
{
    MediumBlocks::instance().release_all([](void* p) noexcept { ::operator delete(p); });
    LargeBlocks::instance().release_all([](void* p) noexcept { aligned_free(p); });
    HugeBlocks::instance().release_all([](void* p) noexcept { aligned_free(p); });
}

} // namespace cmc33::detail

namespace cmc33 {

void set_huge_page_advice(bool advise) noexcept
{
    detail::advise_huge_blocks.store(advise, std::memory_order_relaxed);
}

bool huge_page_advice() noexcept
{
    return detail::advise_huge_blocks.load(std::memory_order_relaxed);
}

} // namespace cmc33
