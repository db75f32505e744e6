#include "io/atomic_file.hpp"

#include <atomic>
#include <cctype>
#include <fstream>
#include <string>

#include <unistd.h>

#include "cmc33/error.hpp"

namespace cmc33::io::detail {

void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write)
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
    const std::filesystem::path temp = dir / temp_name;
    try {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        if (!out) throw Error(Status::io_error, path.string() + ": cannot create a file in " + dir.string());
        write(out);
        out.flush();
        if (!out) throw Error(Status::io_error, path.string() + ": writing failed (disk full?)");
        out.close();
        if (!out) throw Error(Status::io_error, path.string() + ": closing failed (disk full?)");
        std::filesystem::rename(temp, path, ec);
        if (ec) throw Error(Status::io_error, path.string() + ": cannot rename the temporary file: " + ec.message());
    } catch (...) {
        std::filesystem::remove(temp, ec);
        throw;
    }
}

std::string lower_extension(const std::filesystem::path& path)
{
    std::string ext = path.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

} // namespace cmc33::io::detail
