#pragma once
// Writing output files so that a failure never leaves a half-written file behind: the content
// goes to a temporary file in the target's folder, which is renamed over the target only after
// everything was written and flushed.
//
// An interrupted run must not leave them behind either. Every temporary (file or folder) and
// every child process group the library starts is registered here while it exists, and
// remove_temporaries() kills the groups and removes the paths. The CLI calls it from a thread
// that waits for SIGINT, SIGTERM and SIGHUP with sigwait (cli/signals.cpp), not from a signal
// handler: removing a folder tree is not async-signal-safe, and a normal thread may do anything.
// Creating a temporary and registering it happen under the registry's lock, and so do the
// rename that makes it final and its unregistering: a cleanup sees a temporary either whole or
// not at all. After remove_temporaries() the lock stays taken, so no thread creates another
// temporary before the process exits.

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>
#include <string>

#include "cmc33/io_export.hpp" // verify and the CLI call these across the library boundary

namespace cmc33::io::detail {

/// What writing `path` replaces. A symbolic link is written through: the bytes go to the file
/// its links lead to (`target`), and the link stays. An existing target keeps its mode, and its
/// owner and group where the process may set them (root; a group of its own).
struct OutputTarget {
    std::filesystem::path target; ///< `path`, or where its symbolic links lead
    bool exists = false;          ///< `target` is an existing regular file
    mode_t mode = 0;              ///< its permission bits (with set-id and sticky bits)
    uid_t uid = 0;
    gid_t gid = 0;
};

/// The OutputTarget of `path`, checked before anything is written. @throws Error{io_error}
/// naming `path`: a loop of symbolic links, a directory, an existing target that is not a
/// regular file (a device such as /dev/null is never replaced), or one this process may not
/// write (read-only: what `>` in a shell refuses is refused too).
CMC33_IO_EXPORT OutputTarget output_target(const std::filesystem::path& path);

/// Calls write(stream) on a temporary file beside the output_target() of `path`, then renames
/// it over that target (keeping its mode and owner, see OutputTarget). If write throws, or the
/// stream fails, the temporary file is removed and Error{io_error} saying why (or write's own
/// exception) propagates; the target is left as it was.
/// The temporary is `.NAME.tmpPID-N` in the target's folder (temporary_beside).
CMC33_IO_EXPORT void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

/// The name of a new temporary beside `path`: `.NAME.tmpPID-N` in its folder (checked to be a
/// folder: Error{io_error} otherwise, or when `path` is a directory). NAME is the file name of
/// `path` cut to kTemporaryNameBytes bytes (at a character boundary), so that the temporary's
/// name stays short even for a file name of the longest length a folder allows.
CMC33_IO_EXPORT std::filesystem::path temporary_beside(const std::filesystem::path& path);
/// The most bytes of the target's name that a temporary's name repeats.
inline constexpr std::size_t kTemporaryNameBytes = 64;

/// A file written at offsets, in any order (pwrite): a temporary beside the output_target() of
/// `path` (registered, so a signal removes it), renamed over that target by commit(), as
/// write_atomically() does. Destroyed before commit(), it is removed and the target is left as it
/// was. For writers that know where every byte goes (out-of-core slabs).
class CMC33_IO_EXPORT PositionalFile {
public:
    /// @throws Error{io_error} if the temporary cannot be created
    explicit PositionalFile(const std::filesystem::path& path);
    ~PositionalFile();
    PositionalFile(const PositionalFile&) = delete;
    PositionalFile& operator=(const PositionalFile&) = delete;
    /// @throws Error{io_error} naming `path` (disk full, ...)
    void write_at(std::uint64_t offset, const void* data, std::size_t count);
    /// Closes the temporary and renames it to `path`. @throws Error{io_error}
    void commit();

private:
    std::filesystem::path path_;
    std::filesystem::path target_;
    int fd_ = -1;
    std::unique_ptr<class Temporary> temp_;
};

/// Lower-case extension with the dot (".ply"); "" if none.
CMC33_IO_EXPORT std::string lower_extension(const std::filesystem::path& path);

/// A registered temporary file or folder: remove_temporaries() removes it (recursively) until
/// it is committed or destroyed. Destroying it removes it too, unless it was committed.
class CMC33_IO_EXPORT Temporary {
public:
    /// Runs create() (which makes `path`: opens the file, creates the folder) under the
    /// registry's lock, then registers `path`. If create throws, nothing is registered.
    Temporary(std::filesystem::path path, const std::function<void()>& create);
    ~Temporary();
    Temporary(const Temporary&) = delete;
    Temporary& operator=(const Temporary&) = delete;

    /// Runs finish() (the rename that makes the temporary final) under the registry's lock and
    /// unregisters it; it is no longer removed. If finish throws, it stays registered.
    void commit(const std::function<void()>& finish);
    const std::filesystem::path& path() const noexcept { return path_; }

private:
    std::filesystem::path path_;
    std::uint64_t id_ = 0;
    bool committed_ = false;
};

/// Forks under the registry's lock, registers the child's process group (`child` runs in the
/// forked child, must only call async-signal-safe functions and must not return: it puts
/// itself in its own process group and execs). Returns the child's pid, -1 if fork failed.
CMC33_IO_EXPORT pid_t start_child(const std::function<void()>& child);
/// The child has been waited for: its group is no longer killed by remove_temporaries().
CMC33_IO_EXPORT void forget_child(pid_t pid);

/// Kills every registered process group (SIGKILL), removes every registered path, and keeps the
/// registry locked so that nothing new is registered. For a thread that exits the process next.
/// Returns the number of paths removed.
CMC33_IO_EXPORT int remove_temporaries() noexcept;

} // namespace cmc33::io::detail
