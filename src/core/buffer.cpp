// Memory for cmc33::Buffer (include/cmc33/mesh.hpp). A mesh of millions of triangles is written
// once, in parallel; with 4 KiB pages most of that time goes to page faults. Blocks of 4 MiB and
// more are aligned to 2 MiB and advised for transparent huge pages (Linux, when THP is in
// "madvise" or "always" mode; elsewhere the advice is ignored and they are plain pages).

#include <sys/mman.h>

#include <cstdlib>
#include <new>

#include "cmc33/mesh.hpp"

namespace cmc33::detail {

namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kLarge = 2 * kHugePage;
} // namespace

void* allocate_buffer(std::size_t bytes)
{
    if (bytes < kLarge) return ::operator new(bytes);
    void* p = nullptr;
    if (posix_memalign(&p, kHugePage, bytes) != 0) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    (void)madvise(p, bytes & ~(kHugePage - 1), MADV_HUGEPAGE); // advice only: failure is harmless
#endif
    return p;
}

void deallocate_buffer(void* p, std::size_t bytes) noexcept
{
    if (bytes < kLarge) {
        ::operator delete(p);
    } else {
        std::free(p);
    }
}

} // namespace cmc33::detail
