// Memory for cmc33::Buffer (src/base/include/cmc33/mesh.hpp). A mesh of millions of triangles is written
// once, in parallel; with 4 KiB pages most of that time goes to page faults. Blocks of 1 MiB and
// more are rounded up to whole 2 MiB pages, aligned to 2 MiB and advised for transparent huge
// pages (Linux, when THP is in "madvise" or "always" mode; elsewhere the advice is ignored and
// they are plain pages, of which only the ones written count). From 4 MiB down to 2 MiB: stent's
// positions and normals (2 MiB each) took 512 faults apiece, 4 % of its extraction; one-shot runs
// (cmc33 extract --normals --repeat 1, median of 21 processes) went from 9.78 to 8.90 ms on stent
// and from 7.85 to 7.30 ms on aneurism. From 1 MiB, and the tail of a block in a huge page of its
// own (a VM where a 4 KiB fault is dear; medians of 16-30 processes, builds alternating): aneurism 21.7 ->
// 14.7 ms, stent 29.7 -> 13.1 ms, sphere 256^3 30.5 -> 19.3 ms, bonsai 36.1 -> 31.7 ms; the peak
// RSS of `cmc33 extract` on aneurism 28.4 -> 32.0 MiB (at most 2 MiB more per block).
// Freed blocks of up to 16 MiB are kept, up to four, for the next allocation of the same size:
// repeated extractions (an isovalue sweep, `--repeat`, a Python loop) then write memory that is
// already mapped, as glibc's heap gave them for blocks below its mmap threshold before the
// rounding (aneurism, `--repeat 5`, one thread, normals: 9.0 ms with the heap, 12.7 ms with fresh
// huge pages every time on the VM above).
// A failed allocation says how many bytes it wanted: a mesh too large for memory (or for
// `ulimit -v`) is reported as such, and the command line names the file it came from.

#include <array>
#include <cstdlib>
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

[[noreturn]] void out_of_memory(std::size_t bytes)
{
    throw Error(Status::too_large, "cannot allocate " + std::to_string(bytes) + " bytes for the mesh (out of memory)");
}

/// Freed large blocks (whole huge pages, aligned) kept for reuse by size; at most kSlots blocks of
/// at most kLargestKept bytes each.
class BlockCache {
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
    /// Keeps p (of `bytes`) if it is small enough and a slot is free; false: the caller frees it.
    bool keep(void* p, std::size_t bytes) noexcept
    {
        if (bytes > kLargestKept) return false;
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
    static constexpr std::size_t kSlots = 4;
    static constexpr std::size_t kLargestKept = std::size_t{16} << 20;
    struct Block {
        void* p = nullptr;
        std::size_t bytes = 0;
    };
    std::mutex mutex_;
    std::array<Block, kSlots> blocks_{};
};

/// `bytes` rounded up to whole huge pages; 0 when that overflows.
std::size_t whole_pages(std::size_t bytes) noexcept
{
    const std::size_t whole = bytes + (kHugePageBytes - 1 - (bytes - 1) % kHugePageBytes);
    return whole < bytes ? 0 : whole;
}
} // namespace

void* allocate_buffer(std::size_t bytes)
{
    if (bytes < kLarge) {
        void* small = ::operator new(bytes, std::nothrow);
        if (small == nullptr) out_of_memory(bytes);
        return small;
    }
    // whole huge pages: the last one's tail, in 4 KiB pages, took a fault per page written
    const std::size_t whole = whole_pages(bytes);
    if (whole == 0) out_of_memory(bytes);
    if (void* kept = BlockCache::instance().take(whole)) return kept;
    void* p = aligned_allocate(kHugePageBytes, whole);
    if (p == nullptr) out_of_memory(bytes);
    advise_huge_pages(p, whole);
    return p;
}

void deallocate_buffer(void* p, std::size_t bytes) noexcept
{
    if (bytes < kLarge) {
        ::operator delete(p);
    } else if (p != nullptr && !BlockCache::instance().keep(p, whole_pages(bytes))) {
        aligned_free(p);
    }
}

} // namespace cmc33::detail
