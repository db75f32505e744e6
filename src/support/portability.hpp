#pragma once
// The non-portable pieces of the library in one place, each with its fallback:
//
//   Int128 / CMC33_HAS_INT128   128-bit integers (GCC, Clang); without them the decisions take the
//                               filtered-double / GMP path, which gives the same answers, slower
//   aligned_allocate / aligned_free / advise_huge_pages / advise_huge_pages_within
//                               2 MiB-aligned blocks for large meshes (posix_memalign + madvise;
//                               _aligned_malloc on Windows; the advice is a no-op where unknown),
//                               and the same advice for the whole 2 MiB blocks inside a volume's
//                               samples before they are first written
//   balloon_reports_free_memory  whether a VM's balloon hands free memory back to its host, where
//                               Buffer's blocks take no huge pages (src/base/buffer.cpp)
//   map_readonly / unmap        a read-only file mapping for the mesh readers (mmap); nullptr
//                               where there is none, and the caller reads the file instead
//   CMC33_ALWAYS_INLINE         for the extractor's per-row functions, which GCC would otherwise
//                               call out of line (3-4 % more instructions); plain inline elsewhere
//
// The rest of io (open/fstat, fork/exec of verify --cmd, the CLI's sigwait) is POSIX and stays so:
// cmc33 builds on Linux and macOS with GCC or Clang. GCC-only warning flags are chosen by compiler
// in cmake/cmc33_warnings.cmake.

#include <cstddef>
#include <cstdint>
#include <cstdlib>

#if defined(_WIN32)
#include <malloc.h>
#else
#include <sys/mman.h>
#endif
#if !defined(_WIN32)
#include <dirent.h>
#include <fstream>
#include <string>
#endif

#if defined(__GNUC__) || defined(__clang__)
#define CMC33_ALWAYS_INLINE [[gnu::always_inline]] inline
#define CMC33_NOINLINE [[gnu::noinline]]
#else
#define CMC33_ALWAYS_INLINE inline
#define CMC33_NOINLINE
#endif

/// A hint to fetch the cache line at address p (read); nothing where the compiler has no such hint.
#if defined(__GNUC__) || defined(__clang__)
#define CMC33_PREFETCH(p) __builtin_prefetch(p)
#else
#define CMC33_PREFETCH(p) ((void)(p))
#endif

namespace cmc33::detail {

#if defined(__SIZEOF_INT128__)
#define CMC33_HAS_INT128 1
__extension__ typedef __int128 Int128;
__extension__ typedef unsigned __int128 UInt128;
#else
#define CMC33_HAS_INT128 0
#endif

/// `bytes` aligned to `alignment` (a power of two, a multiple of sizeof(void*)), or nullptr.
inline void* aligned_allocate(std::size_t alignment, std::size_t bytes) noexcept
{
#if defined(_WIN32)
    return _aligned_malloc(bytes, alignment);
#else
    void* p = nullptr;
    return posix_memalign(&p, alignment, bytes) == 0 ? p : nullptr;
#endif
}

inline void aligned_free(void* p) noexcept
{
#if defined(_WIN32)
    _aligned_free(p);
#else
    std::free(p);
#endif
}

/// The size of an x86-64 transparent huge page: the unit of advise_huge_pages_within and of
/// Buffer's large blocks (src/base/buffer.cpp).
inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

#if !defined(_WIN32)
/// balloon_reports_free_memory() for the virtio devices listed in directory `root` (Linux's sysfs;
/// any POSIX system can read such a tree, which the tests make).
inline bool balloon_reports_free_memory_in(const std::string& root)
{
    DIR* dir = ::opendir(root.c_str());
    if (dir == nullptr) return false;
    bool reports = false;
    while (const dirent* entry = ::readdir(dir)) {
        if (entry->d_name[0] == '.') continue;
        const std::string device = root + entry->d_name;
        std::string id, features;
        std::ifstream(device + "/device") >> id;
        if (id != "0x0005") continue;
        std::ifstream(device + "/features") >> features; // one '0' or '1' per feature bit
        reports = reports || (features.size() > 5 && features[5] == '1');
    }
    ::closedir(dir);
    return reports;
}
#endif

/// Whether this Linux machine is a VM whose memory balloon reports free memory to its host
/// (a virtio device of id 5, the balloon, that negotiated feature bit 5, VIRTIO_BALLOON_F_REPORTING):
/// free blocks of 2 MiB and more that any process gave back are then returned to the host, and
/// writing one again costs a fault in the host for each of its pages. Reads sysfs; false elsewhere.
inline bool balloon_reports_free_memory() noexcept
{
#if defined(__linux__)
    try {
        return balloon_reports_free_memory_in("/sys/bus/virtio/devices/");
    } catch (...) { // a string that cannot be allocated: no advice either way
        return false;
    }
#else
    return false;
#endif
}

/// Asks for transparent huge pages on [p, p + bytes) (Linux); advice only, failure is harmless.
inline void advise_huge_pages([[maybe_unused]] void* p, [[maybe_unused]] std::size_t bytes) noexcept
{
#if defined(MADV_HUGEPAGE)
    (void)madvise(p, bytes, MADV_HUGEPAGE);
#endif
}

/// advise_huge_pages on the whole 2 MiB blocks inside [p, p + bytes), for memory from new[] that
/// has not been written yet: its first writes then fault in 2 MiB pages, not 4 KiB ones (the
/// 512 MiB of a 512^3 float volume: 256 faults instead of 131,072, and the passes that read it
/// miss the TLB 512 times less often). Nothing below 2 MiB.
inline void advise_huge_pages_within([[maybe_unused]] void* p, [[maybe_unused]] std::size_t bytes) noexcept
{
#if defined(MADV_HUGEPAGE)
    const auto begin = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t first = (begin + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
    const std::uintptr_t last = (begin + bytes) & ~(kHugePageBytes - 1);
    if (last > first) advise_huge_pages(reinterpret_cast<void*>(first), last - first);
#endif
}

/// The first `bytes` of open file `fd`, mapped read-only and advised for sequential reading;
/// nullptr if it cannot be mapped (the caller reads the file instead).
inline const void* map_readonly([[maybe_unused]] int fd, [[maybe_unused]] std::size_t bytes) noexcept
{
#if defined(_WIN32)
    return nullptr;
#else
    void* map = ::mmap(nullptr, bytes, PROT_READ, MAP_PRIVATE, fd, 0);
    if (map == MAP_FAILED) return nullptr;
#if defined(MADV_SEQUENTIAL)
    (void)::madvise(map, bytes, MADV_SEQUENTIAL);
#endif
    return map;
#endif
}

inline void unmap([[maybe_unused]] const void* map, [[maybe_unused]] std::size_t bytes) noexcept
{
#if !defined(_WIN32)
    if (map != nullptr) ::munmap(const_cast<void*>(map), bytes);
#endif
}

} // namespace cmc33::detail
