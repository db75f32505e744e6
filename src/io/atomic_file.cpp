#include "atomic_file.hpp"

#include <atomic>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <streambuf>
#include <string>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
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

namespace {

/// Symbolic links followed to an output's file at most (the kernel's own limit for one path).
constexpr int kMaxLinks = 40;

std::string reason(int error)
{
    return std::strerror(error);
}

/// " (a symbolic link to TARGET)" when the bytes go elsewhere than `path` names, for messages.
std::string through(const std::filesystem::path& path, const std::filesystem::path& target)
{
    return target == path ? std::string() : " (" + path.string() + " is a symbolic link to " + target.string() + ")";
}

std::filesystem::path folder_of(const std::filesystem::path& path)
{
    return path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
}

/// `.NAME.tmpPID-N` beside `path`, NAME cut to kTemporaryNameBytes bytes.
std::filesystem::path temporary_name(const std::filesystem::path& path)
{
    static std::atomic<unsigned> counter{0};
    std::string name = path.filename().string();
    if (name.size() > kTemporaryNameBytes) {
        std::size_t cut = kTemporaryNameBytes;
        // Not inside a UTF-8 character: its continuation bytes are 10xxxxxx.
        while (cut > 0 && (static_cast<unsigned char>(name[cut]) & 0xC0) == 0x80) --cut;
        name.resize(cut);
    }
    std::string temp_name = "."; // built piecewise: g++ 12 warns falsely on "." + string (-Wrestrict)
    temp_name += name;
    temp_name += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    return folder_of(path) / temp_name;
}

/// The temporary that replaces `output`: private (0600) while it replaces an existing file, whose
/// owner, group and mode it takes at once; otherwise 0666 less the umask, as any new file.
/// Returns the descriptor, or -1 with `error` set (the temporary is not left behind).
int create_file(const std::filesystem::path& temp, const OutputTarget& output, int& error)
{
    const auto open_new = [&] {
        return ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, output.exists ? 0600 : 0666);
    };
    int fd = open_new();
    if (fd < 0 && errno == EEXIST && ::unlink(temp.c_str()) == 0) {
        fd = open_new(); // a leftover of a killed process that had this pid: its temporaries are ours to remove
    }
    if (fd < 0) {
        error = errno;
        return -1;
    }
    if (output.exists) {
        // Owner before mode: chown clears set-id bits. Not root: at least the group, if one of ours;
        // failing both, the file is ours (documented in docs/cli.md).
        if (::fchown(fd, output.uid, output.gid) != 0 && ::fchown(fd, static_cast<uid_t>(-1), output.gid) != 0) {
        }
        if (::fchmod(fd, output.mode) != 0) {
            error = errno;
            ::close(fd);
            ::unlink(temp.c_str());
            return -1;
        }
    }
    return fd;
}

/// The temporary beside `output.target`, with a message naming `path` when its folder is missing.
std::filesystem::path temporary_for(const std::filesystem::path& path, const OutputTarget& output)
{
    const std::filesystem::path dir = folder_of(output.target);
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) {
        throw Error(Status::io_error, path.string() + ": cannot write, folder " + dir.string() + " does not exist" +
                                          through(path, output.target));
    }
    return temporary_name(output.target);
}

std::string create_failed(const std::filesystem::path& path, const std::filesystem::path& temp, int error)
{
    return path.string() + ": cannot create a file in " + folder_of(temp).string() + " (" + reason(error) + ")";
}

/// An output stream on a file descriptor that keeps the errno of a failed write, so that the
/// message says why (a std::ofstream says only that it failed).
class DescriptorBuffer final : public std::streambuf {
public:
    explicit DescriptorBuffer(int fd) : fd_(fd), buffer_(std::size_t{1} << 16)
    {
        setp(buffer_.data(), buffer_.data() + buffer_.size());
    }
    int error() const noexcept { return error_; }

protected:
    int_type overflow(int_type c) override
    {
        if (!drain()) return traits_type::eof();
        if (!traits_type::eq_int_type(c, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(c);
            pbump(1);
        }
        return traits_type::not_eof(c);
    }
    std::streamsize xsputn(const char* data, std::streamsize count) override
    {
        if (count < static_cast<std::streamsize>(buffer_.size())) return std::streambuf::xsputn(data, count);
        // Large blocks (the samples) go straight to the file, without a copy.
        if (!drain() || !write_all(data, static_cast<std::size_t>(count))) return 0;
        return count;
    }
    int sync() override { return drain() ? 0 : -1; }

private:
    bool write_all(const char* data, std::size_t count)
    {
        while (count > 0) {
            const ::ssize_t n = ::write(fd_, data, std::min<std::size_t>(count, std::size_t{1} << 30));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                error_ = n < 0 ? errno : EIO;
                return false;
            }
            data += n, count -= static_cast<std::size_t>(n);
        }
        return true;
    }
    bool drain()
    {
        const std::size_t pending = static_cast<std::size_t>(pptr() - pbase());
        setp(buffer_.data(), buffer_.data() + buffer_.size());
        return error_ == 0 && write_all(buffer_.data(), pending);
    }

    int fd_;
    int error_ = 0;
    std::vector<char> buffer_;
};

/// Closes a descriptor once, reporting close()'s errno (a delayed write error, NFS quota, ...).
class Descriptor {
public:
    explicit Descriptor(int fd) : fd_(fd) {}
    ~Descriptor()
    {
        if (fd_ >= 0) ::close(fd_);
    }
    Descriptor(const Descriptor&) = delete;
    Descriptor& operator=(const Descriptor&) = delete;
    int close_now()
    {
        const int rc = ::close(std::exchange(fd_, -1));
        return rc == 0 ? 0 : errno;
    }

private:
    int fd_;
};

} // namespace

OutputTarget output_target(const std::filesystem::path& path)
{
    OutputTarget output;
    std::filesystem::path p = path;
    struct stat st {};
    for (int links = 0;; ++links) {
        if (::lstat(p.c_str(), &st) != 0) {
            const int error = errno;
            output.target = p;
            if (error == ENOENT) return output; // a new file (or the new target of a dangling link)
            throw Error(Status::io_error, path.string() + ": cannot write: " + reason(error) + through(path, p));
        }
        if (!S_ISLNK(st.st_mode)) break;
        if (links == kMaxLinks) {
            throw Error(Status::io_error, path.string() + ": cannot write: more than " + std::to_string(kMaxLinks) +
                                              " symbolic links to follow (a loop?)");
        }
        std::error_code ec;
        const std::filesystem::path to = std::filesystem::read_symlink(p, ec);
        if (ec) {
            throw Error(Status::io_error, path.string() + ": cannot write: cannot read the symbolic link " +
                                              p.string() + " (" + ec.message() + ")");
        }
        p = to.is_absolute() ? to : p.parent_path() / to;
    }
    output.target = p;
    // "it", or the file the links lead to, for messages.
    const std::string it = p == path ? std::string("it") : "its target " + p.string();
    if (S_ISDIR(st.st_mode)) throw Error(Status::io_error, path.string() + ": cannot write: " + it + " is a directory");
    if (!S_ISREG(st.st_mode)) {
        throw Error(Status::io_error, path.string() + ": cannot write: " + it +
                                          " is not a regular file (a device, pipe or socket); cmc33 replaces "
                                          "regular files only");
    }
    if (::faccessat(AT_FDCWD, p.c_str(), W_OK, AT_EACCESS) != 0) {
        const int error = errno;
        char mode[8];
        std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
        throw Error(Status::io_error, path.string() + ": cannot write: " + it + " is not writable (" + reason(error) +
                                          ", mode " + mode + "); make it writable or remove it to replace it");
    }
    output.exists = true;
    output.mode = st.st_mode & 07777;
    output.uid = st.st_uid;
    output.gid = st.st_gid;
    return output;
}

std::filesystem::path temporary_beside(const std::filesystem::path& path)
{
    const std::filesystem::path dir = folder_of(path);
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) {
        throw Error(Status::io_error, path.string() + ": cannot write, folder " + dir.string() + " does not exist");
    }
    if (std::filesystem::is_directory(path, ec)) {
        throw Error(Status::io_error, path.string() + ": cannot write, it is a directory");
    }
    return temporary_name(path);
}

void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write)
{
    const OutputTarget output = output_target(path);
    const std::filesystem::path temp_path = temporary_for(path, output);
    int fd = -1, error = 0;
    Temporary temp(temp_path, [&] { fd = create_file(temp_path, output, error); });
    if (fd < 0) throw Error(Status::io_error, create_failed(path, temp_path, error));
    Descriptor file(fd);
    DescriptorBuffer buffer(fd);
    std::ostream out(&buffer);
    write(out);
    out.flush();
    if (!out) {
        throw Error(Status::io_error, path.string() + ": writing failed (" +
                                          (buffer.error() != 0 ? reason(buffer.error()) : "stream error") + ")");
    }
    if (const int close_error = file.close_now(); close_error != 0) {
        throw Error(Status::io_error, path.string() + ": closing failed (" + reason(close_error) + ")");
    }
    temp.commit([&] {
        std::error_code ec;
        std::filesystem::rename(temp.path(), output.target, ec);
        if (ec) throw Error(Status::io_error, path.string() + ": cannot rename the temporary file: " + ec.message());
    });
}

PositionalFile::PositionalFile(const std::filesystem::path& path) : path_(path)
{
    const OutputTarget output = output_target(path);
    target_ = output.target;
    const std::filesystem::path temp_path = temporary_for(path, output);
    int error = 0;
    temp_ = std::make_unique<Temporary>(temp_path, [&] { fd_ = create_file(temp_path, output, error); });
    if (fd_ < 0) throw Error(Status::io_error, create_failed(path, temp_path, error));
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
        const ::ssize_t n =
            ::pwrite(fd_, p, std::min<std::size_t>(count, std::size_t{1} << 30), static_cast<::off_t>(offset));
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
    if (::close(fd) != 0) {
        const int error = errno;
        throw Error(Status::io_error, path_.string() + ": closing failed (" + reason(error) + ")");
    }
    temp_->commit([&] {
        std::error_code ec;
        std::filesystem::rename(temp_->path(), target_, ec);
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
