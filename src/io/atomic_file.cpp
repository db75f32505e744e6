#include "atomic_file.hpp"

#include <atomic>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cmc33/error.hpp"

namespace cmc33::io::detail {

namespace {

/// The temporaries and child process groups of the process (see atomic_file.hpp).
struct Registry {
    std::mutex mutex;
    std::vector<std::pair<std::uint64_t, std::filesystem::path>> paths;
    std::vector<pid_t> children;
    std::uint64_t next_id = 1;
};

/// Never destroyed: a signal may arrive while static objects are destroyed at exit.
Registry& registry()
{
    static Registry* const r = new Registry;
    return *r;
}

void unregister(Registry& r, std::uint64_t id)
{
    for (auto it = r.paths.begin(); it != r.paths.end(); ++it) {
        if (it->first == id) {
            r.paths.erase(it);
            return;
        }
    }
}

} // namespace

Temporary::Temporary(std::filesystem::path path, const std::function<void()>& create) : path_(std::move(path))
{
    Registry& r = registry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    r.paths.reserve(r.paths.size() + 1); // registering after create() must not fail
    create();
    id_ = r.next_id++;
    r.paths.emplace_back(id_, path_);
}

Temporary::~Temporary()
{
    if (committed_) return;
    Registry& r = registry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
    unregister(r, id_);
}

void Temporary::commit(const std::function<void()>& finish)
{
    Registry& r = registry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    finish();
    unregister(r, id_);
    committed_ = true;
}

pid_t start_child(const std::function<void()>& child)
{
    Registry& r = registry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    r.children.reserve(r.children.size() + 1);
    const pid_t pid = ::fork();
    if (pid == 0) {
        child();
        ::_exit(127);
    }
    if (pid > 0) {
        ::setpgid(pid, pid); // the child does it too: whichever runs first, the group exists
        r.children.push_back(pid);
    }
    return pid;
}

void forget_child(pid_t pid)
{
    Registry& r = registry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    for (auto it = r.children.begin(); it != r.children.end(); ++it) {
        if (*it == pid) {
            r.children.erase(it);
            return;
        }
    }
}

int remove_temporaries() noexcept
{
    Registry& r = registry();
    r.mutex.lock(); // kept: nothing is registered between the cleanup and the exit
    for (const pid_t pid : r.children) ::kill(-pid, SIGKILL);
    for (const pid_t pid : r.children) {
        // Wait until the child is dead (without reaping it: its own waitpid may be running), so
        // that it writes nothing into a folder removed below.
        siginfo_t info;
        while (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT) == -1 && errno == EINTR) {
        }
    }
    int removed = 0;
    for (const auto& entry : r.paths) {
        try {
            std::error_code ec;
            if (std::filesystem::remove_all(entry.second, ec) > 0) ++removed;
        } catch (...) { // bad_alloc: remove what can be removed
        }
    }
    return removed;
}

std::filesystem::path temporary_beside(const std::filesystem::path& path)
{
    static std::atomic<unsigned> counter{0};
    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) {
        throw Error(Status::io_error, path.string() + ": cannot write, folder " + dir.string() + " does not exist");
    }
    if (std::filesystem::is_directory(path, ec)) {
        throw Error(Status::io_error, path.string() + ": cannot write, it is a directory");
    }
    std::string temp_name = ".";  // built piecewise: g++ 12 warns falsely on "." + string (-Wrestrict)
    temp_name += path.filename().string();
    temp_name += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    return dir / temp_name;
}

void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write)
{
    const std::filesystem::path temp_path = temporary_beside(path);
    const std::filesystem::path dir = temp_path.parent_path();
    std::error_code ec;
    std::ofstream out;
    Temporary temp(temp_path, [&] { out.open(temp_path, std::ios::binary | std::ios::trunc); });
    if (!out) throw Error(Status::io_error, path.string() + ": cannot create a file in " + dir.string());
    write(out);
    out.flush();
    if (!out) throw Error(Status::io_error, path.string() + ": writing failed (disk full?)");
    out.close();
    if (!out) throw Error(Status::io_error, path.string() + ": closing failed (disk full?)");
    temp.commit([&] {
        std::filesystem::rename(temp.path(), path, ec);
        if (ec) throw Error(Status::io_error, path.string() + ": cannot rename the temporary file: " + ec.message());
    });
}

PositionalFile::PositionalFile(const std::filesystem::path& path) : path_(path)
{
    const std::filesystem::path temp_path = temporary_beside(path);
    int error = 0;
    temp_ = std::make_unique<Temporary>(temp_path, [&] {
        fd_ = ::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        error = errno;
    });
    if (fd_ < 0) {
        throw Error(Status::io_error, path.string() + ": cannot create a file in " + temp_path.parent_path().string() +
                                          " (" + std::strerror(error) + ")");
    }
}

PositionalFile::~PositionalFile()
{
    if (fd_ >= 0) ::close(fd_);
    temp_.reset(); // removes the temporary unless committed
}

void PositionalFile::write_at(std::uint64_t offset, const void* data, std::size_t count)
{
    const auto* p = static_cast<const unsigned char*>(data);
    while (count > 0) {
        const ::ssize_t n = ::pwrite(fd_, p, std::min<std::size_t>(count, std::size_t{1} << 30), static_cast<::off_t>(offset));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            throw Error(Status::io_error, path_.string() + ": writing failed at byte " + std::to_string(offset) + " (" +
                                              (n < 0 ? std::strerror(errno) : "nothing written") + "; disk full?)");
        }
        p += n, offset += static_cast<std::uint64_t>(n), count -= static_cast<std::size_t>(n);
    }
}

void PositionalFile::commit()
{
    const int fd = std::exchange(fd_, -1);
    if (::close(fd) != 0) throw Error(Status::io_error, path_.string() + ": closing failed (disk full?)");
    temp_->commit([&] {
        std::error_code ec;
        std::filesystem::rename(temp_->path(), path_, ec);
        if (ec) throw Error(Status::io_error, path_.string() + ": cannot rename the temporary file: " + ec.message());
    });
}

std::string lower_extension(const std::filesystem::path& path)
{
    std::string ext = path.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

} // namespace cmc33::io::detail
