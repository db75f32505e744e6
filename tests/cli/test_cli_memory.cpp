// The real `cmc33` executable (CMC33_EXE) under a virtual-memory limit (`ulimit -v`, i.e.
// RLIMIT_AS): a volume or mesh larger than memory is one line on stderr naming the file and what
// ran out, exit 1, no crash, and no output file or temporary left in the output folder.
// AddressSanitizer and ThreadSanitizer reserve terabytes of shadow memory at start-up, so under
// them no such limit can be set: the tests skip themselves there.

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "test_support.hpp"

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define CMC33_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define CMC33_SANITIZED 1
#endif

namespace cmc33 {
namespace {

namespace fs = std::filesystem;

/// Address space for the child, in KiB: the executable and its libraries need about 30 MB,
/// every volume and mesh below needs far more.
constexpr int kLimitKib = 300 * 1024;

struct Result {
    int code = -1;
    std::string err;
};

std::string quote(const std::string& s)
{
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

/// `cmc33 ARGS` in a shell whose address space is limited to `limit_kib`; stdout discarded.
Result run_limited(const std::string& args, const fs::path& dir, int limit_kib = kLimitKib)
{
    const fs::path err_file = dir / "stderr.txt";
    const std::string command = "ulimit -v " + std::to_string(limit_kib) + " && exec " + quote(CMC33_EXE) + " " +
                                args + " >/dev/null 2>" + quote(err_file.string()) + " </dev/null";
    const int status = std::system(command.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.err = test::read_file(err_file);
    fs::remove(err_file);
    return r;
}

/// A file of `bytes` zero bytes that occupies no disk (sparse).
void sparse_file(const fs::path& path, std::uint64_t bytes)
{
    { std::ofstream(path, std::ios::binary); }
    fs::resize_file(path, bytes);
}

bool one_line(const std::string& s) { return !s.empty() && s.find('\n') == s.size() - 1; }

std::size_t entries(const fs::path& dir)
{
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
}

/// `count` random bytes (uint8 noise: the roughest surfaces, the most triangles per sample) at `path`.
fs::path write_noise(const fs::path& path, std::size_t count)
{
    std::string bytes(count, '\0');
    std::mt19937 rng(9);
    for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
    test::write_file(path, bytes);
    return path;
}

class OutOfMemory : public ::testing::Test {
protected:
    void SetUp() override
    {
#ifdef CMC33_SANITIZED
        GTEST_SKIP() << "a sanitizer's shadow memory does not fit under ulimit -v";
#endif
        dir_ = test::temp_dir();
        out_ = dir_ / "out";
        fs::create_directories(out_);
    }
    /// Exit 1, one line naming `file` and containing `says`, and nothing left in out/.
    void expect_clean_failure(const Result& r, const std::string& file, const std::string& says)
    {
        EXPECT_EQ(r.code, 1) << r.err;
        EXPECT_TRUE(one_line(r.err)) << r.err;
        EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
        EXPECT_EQ(entries(out_), 0u) << "a file was left in " << out_;
    }
    fs::path dir_, out_;
};

TEST_F(OutOfMemory, ARawVolumeLargerThanTheLimitIsRefusedNamingItsSize)
{
    const fs::path raw = dir_ / "big.raw";
    sparse_file(raw, 1000ull * 1000 * 1000);
    const std::string volume = quote(raw.string()) + " --dims 1000 1000 1000 --type uint8";
    expect_clean_failure(run_limited("extract " + volume + " -i 100 -o " + quote((out_ / "m.ply").string()), dir_),
                         raw.string(), "cannot allocate 1000000000 bytes for a 1000x1000x1000 uint8 volume");
    expect_clean_failure(run_limited("info " + volume, dir_), raw.string(), "cannot allocate 1000000000 bytes");
}

TEST_F(OutOfMemory, AMeshLargerThanTheLimitIsRefusedNamingTheVolume)
{
    // 160^3 random bytes: 4 MB in, 7 million vertices and 15 million triangles out (270 MB).
    const fs::path raw = write_noise(dir_ / "noise.raw", 160 * 160 * 160);
    const fs::path mesh = out_ / "noise.ply";
    const std::string args = "extract " + quote(raw.string()) + " --dims 160 160 160 --type uint8 -i 127.5 " +
                             "--threads 2 -o " + quote(mesh.string());
    expect_clean_failure(run_limited(args, dir_), raw.string(), "bytes for the mesh (out of memory)");
    // 500 MB: the mesh (about 270 MB) fits, and so does its check, slab by slab (the general
    // checks, 24 bytes per triangle for the topology and more for the geometry, need 360 MB more).
    // It needs about 430 MB of address space; the rest is room for glibc's per-thread arenas,
    // which a loaded machine may create or not.
    const Result fits = run_limited(args + " --json", dir_, 500 * 1024);
    EXPECT_EQ(fits.code, 0) << fits.err;
    EXPECT_TRUE(fs::exists(mesh));
}

TEST_F(OutOfMemory, AMeshFileLargerThanTheLimitIsRefusedByTopo)
{
    // A binary PLY whose header declares 50 million vertices and faces, with the bytes there
    // (sparse zeros): reading it needs more than the limit.
    const fs::path ply = dir_ / "big.ply";
    const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex 50000000\n"
                               "property float x\nproperty float y\nproperty float z\n"
                               "element face 50000000\nproperty list uchar uint vertex_indices\nend_header\n";
    test::write_file(ply, header);
    fs::resize_file(ply, header.size() + 50000000ull * 12 + 50000000ull * 13);
    expect_clean_failure(run_limited("topo " + quote(ply.string()), dir_), ply.string(), "out of memory");
}

/// The peak resident memory, in KiB, of `cmc33 ARGS` (run by a forked child, whose own children
/// are then only this one); -1 if it did not exit 0.
long peak_kib(const std::string& args)
{
    const std::string command = "exec " + quote(CMC33_EXE) + " " + args + " >/dev/null 2>&1 </dev/null";
    int pipe_fds[2];
    if (pipe(pipe_fds) != 0) return -1;
    const pid_t pid = fork();
    if (pid == 0) {
        close(pipe_fds[0]);
        const int status = std::system(command.c_str());
        rusage usage{};
        getrusage(RUSAGE_CHILDREN, &usage);
        const long kib = WIFEXITED(status) && WEXITSTATUS(status) == 0 ? usage.ru_maxrss : -1;
        const bool written = write(pipe_fds[1], &kib, sizeof kib) == static_cast<ssize_t>(sizeof kib);
        _exit(written ? 0 : 1);
    }
    close(pipe_fds[1]);
    long kib = -1;
    if (pid < 0 || read(pipe_fds[0], &kib, sizeof kib) != static_cast<ssize_t>(sizeof kib)) kib = -1;
    close(pipe_fds[0]);
    if (pid > 0) waitpid(pid, nullptr, 0);
    return kib;
}

TEST_F(OutOfMemory, TheMemoryLimitHoldsForTheWholeRunWithTheChecksOnNoise)
{
    // 192x128x14 random bytes: 1.2 million triangles, each slab one or two planes; the checks'
    // working memory (mesh_geometry) held more than the estimate, and what each slab freed stayed
    // in the process (peak 66 MiB at 64M).
    const fs::path raw = write_noise(dir_ / "noise.raw", 192 * 128 * 14);
    const long peak = peak_kib("extract " + quote(raw.string()) + " --dims 192 128 14 --type uint8 -i 127.5 --threads 2 " +
                               "--memory-limit 64M -o " + quote((out_ / "noise.ply").string()));
    ASSERT_GT(peak, 0) << "cmc33 extract --memory-limit 64M failed";
    EXPECT_LE(peak, 64 * 1024) << "peak RSS " << peak << " KiB";
}

} // namespace
} // namespace cmc33
