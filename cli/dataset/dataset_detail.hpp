#pragma once
// What the verification dataset's files share (cli/dataset): text clipping for messages, a cell's
// corner values, and the external command's run and temporary folder. Internal to
// cmc33_cli_dataset.

#include <array>
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

#include <unistd.h>

#include "cmc33/error.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/volume.hpp"
#include "atomic_file.hpp"
#include "dataset.hpp"

namespace cmc33::cli::dataset_detail {

/// `text`, cut to `max_chars` and "..." if it is longer (manifest fields and tool output in messages).
std::string clip(std::string text, std::size_t max_chars = 60);

/// The 8 samples of a 2x2x2 volume in corner order (x fastest), as analyze_cell takes them.
std::array<double, 8> corner_values(const Volume& volume);

/// The temporary folder of the external command's outputs, registered so that a signal removes
/// it too (io/atomic_file.hpp); the destructor removes it.
struct TempFolder {
    std::filesystem::path path;
    io::detail::Temporary temp;
    TempFolder() : path(fresh_path()), temp(path, [this] { create(); }) {}

private:
    static std::filesystem::path fresh_path()
    {
        const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
        return std::filesystem::temp_directory_path() /
               ("cmc33-verify-" + std::to_string(::getpid()) + "-" + std::to_string(stamp));
    }
    void create() const
    {
        std::error_code ec;
        std::filesystem::create_directories(path, ec);
        if (ec)
            throw Error(Status::io_error,
                        path.string() + ": cannot create a temporary folder: " + ec.message());
    }
};

struct CommandResult {
    std::optional<Mesh> mesh;
    std::string note; ///< why there is no mesh
};

/// Runs the command (its output to `log`) and reads the mesh it wrote; none, with the reason, if it
/// failed, timed out (after `timeout_seconds`, <= 0: no limit) or wrote no readable mesh.
CommandResult run_command(const ExternalCommand& command, const std::filesystem::path& log, double timeout_seconds);

} // namespace cmc33::cli::dataset_detail
