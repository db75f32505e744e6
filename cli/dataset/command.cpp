// The external extractor of `cmc33 verify --dataset --cmd`: its command template expanded for one
// field, run by /bin/sh -c in a process group of its own (killed whole on a timeout), its mesh read
// back, and the temporary folder of its outputs.

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>

#include <pthread.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "atomic_file.hpp"
#include "dataset.hpp"
#include "dataset_detail.hpp"
#include "verify_detail.hpp"

namespace cmc33::cli {
namespace dataset_detail {
namespace {

using verification::detail::number_text;
using verification::detail::shell_quote;

std::string last_line(const std::filesystem::path& log)
{
    std::ifstream in(log, std::ios::binary);
    std::string line, last;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.find_first_not_of(" \t") != std::string::npos) last = line;
    }
    return clip(last, 300);
}

/// Runs the shell line in its own process group, so that a timeout or a signal kills the whole
/// tool (a shell may have started several processes). Returns the wait status, or -1 if it could
/// not start; `timed_out` is set if it was killed after `timeout_seconds` (<= 0: no limit).
int run_shell(const std::string& line, double timeout_seconds, bool& timed_out)
{
    timed_out = false;
    const char* const argv[] = {"/bin/sh", "-c", line.c_str(), nullptr};
    const pid_t pid = io::detail::start_child([&argv] {
        // In the forked child: async-signal-safe calls only, then exec.
        ::setpgid(0, 0);
        sigset_t none;
        sigemptyset(&none);
        ::pthread_sigmask(SIG_SETMASK, &none, nullptr); // the CLI blocks SIGINT/SIGTERM/SIGHUP
        ::execv(argv[0], const_cast<char* const*>(argv));
    });
    if (pid < 0) return -1;
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(timeout_seconds));
    auto pause = std::chrono::microseconds(100); // most tools take milliseconds: poll often, then less
    int status = 0;
    for (;;) {
        const pid_t r = ::waitpid(pid, &status, WNOHANG);
        if (r == pid) break;
        if (r < 0 && errno != EINTR) {
            status = -1;
            break;
        }
        if (timeout_seconds > 0 && std::chrono::steady_clock::now() >= deadline) {
            ::kill(-pid, SIGKILL);
            while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
            }
            timed_out = true;
            break;
        }
        std::this_thread::sleep_for(pause);
        pause = std::min<std::chrono::microseconds>(pause * 2, std::chrono::milliseconds(20));
    }
    io::detail::forget_child(pid);
    return status;
}

} // namespace

CommandResult run_command(const ExternalCommand& command, const std::filesystem::path& log,
                          double timeout_seconds)
{
    std::error_code ec;
    std::filesystem::remove(command.output, ec);
    // the newline ends a `#` comment the template may hold, which would otherwise swallow the ")"
    const std::string line =
        "(" + command.shell + "\n) >" + shell_quote(log.string()) + " 2>&1 </dev/null";
    bool timed_out = false;
    const int status = run_shell(line, timeout_seconds, timed_out);
    CommandResult result;
    if (status == -1) {
        result.note = "could not start the command (fork or wait failed)";
        return result;
    }
    if (timed_out) {
        result.note = "the command did not finish within " + number_text(timeout_seconds) +
                      " s (--timeout) and was killed";
    } else if (WIFSIGNALED(status)) {
        result.note = "the command was killed by signal " + std::to_string(WTERMSIG(status));
    } else if (WIFEXITED(status) && WEXITSTATUS(status) != 0) {
        result.note = "the command exited with status " + std::to_string(WEXITSTATUS(status));
    } else if (!std::filesystem::exists(command.output)) {
        result.note = "the command wrote no " + command.output.filename().string();
    } else {
        try {
            result.mesh = io::read_mesh(command.output);
        } catch (const Error& e) {
            result.note = std::string("its mesh does not read: ") + e.what();
        }
    }
    if (!result.mesh) {
        const std::string said = last_line(log);
        if (!said.empty()) result.note += "; it said: " + said;
    }
    std::filesystem::remove(command.output, ec);
    return result;
}

} // namespace dataset_detail

ExternalCommand expand_command(std::string_view command_template, const std::filesystem::path& in,
                               double iso, const std::filesystem::path& out_base)
{
    using dataset_detail::clip;
    using verification::detail::number_text;
    using verification::detail::shell_quote;
    const std::string_view kIn = "{in}", kIso = "{iso}", kOut = "{out}";
    const std::size_t out_at = command_template.find(kOut);
    for (const std::string_view needed : {kIn, kOut}) {
        if (command_template.find(needed) == std::string_view::npos) {
            throw Error(Status::invalid_argument,
                        "command \"" + clip(std::string(command_template)) + "\" has no " +
                            std::string(needed) + "; expected placeholders {in}, {iso} and {out}");
        }
    }
    ExternalCommand command;
    std::string out_text = out_base.string();
    std::string extension = ".ply";
    bool extension_given = false;
    const std::string_view after = command_template.substr(out_at + kOut.size());
    for (std::string_view ext : {".ply", ".obj", ".off", ".stl"}) {
        if (after.size() >= ext.size() && after.substr(0, ext.size()) == ext &&
            (after.size() == ext.size() ||
             !std::isalnum(static_cast<unsigned char>(after[ext.size()])))) {
            extension = std::string(ext);
            extension_given = true;
        }
    }
    command.output = out_text + extension;
    const std::string out_quoted = shell_quote(extension_given ? out_text : out_text + extension);
    const std::string in_quoted = shell_quote(in.string());
    const std::string iso_text = number_text(iso);
    for (std::size_t i = 0; i < command_template.size();) {
        const std::string_view rest = command_template.substr(i);
        if (rest.substr(0, kIn.size()) == kIn) {
            command.shell += in_quoted;
            i += kIn.size();
        } else if (rest.substr(0, kIso.size()) == kIso) {
            command.shell += iso_text;
            i += kIso.size();
        } else if (rest.substr(0, kOut.size()) == kOut) {
            command.shell += out_quoted;
            i += kOut.size();
        } else {
            command.shell += command_template[i++];
        }
    }
    return command;
}

} // namespace cmc33::cli
