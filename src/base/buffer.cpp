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
// A failed allocation says how many bytes it wanted: a mesh too large for memory (or for
// `ulimit -v`) is reported as such, and the command line names the file it came from.

#include <cstdlib>
#include <new>
#include <string>

#include "cmc33/error.hpp"
#include "cmc33/mesh.hpp"
#include "portability.hpp"

namespace cmc33::detail {

namespace {
constexpr std::size_t kHugePage = kHugePageBytes;
constexpr std::size_t kLarge = kHugePage / 2;

[[noreturn]] void out_of_memory(std::size_t bytes)
{
    throw Error(Status::too_large, "cannot allocate " + std::to_string(bytes) + " bytes for the mesh (out of memory)");
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
    const std::size_t whole = bytes + (kHugePage - 1 - (bytes - 1) % kHugePage);
    if (whole < bytes) out_of_memory(bytes);
    void* p = aligned_allocate(kHugePage, whole);
    if (p == nullptr) out_of_memory(bytes);
    advise_huge_pages(p, whole);
    return p;
}

void deallocate_buffer(void* p, std::size_t bytes) noexcept
{
    if (bytes < kLarge) {
        ::operator delete(p);
    } else {
        aligned_free(p);
    }
}

} // namespace cmc33::detail
