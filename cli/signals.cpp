// What an interrupted run leaves behind: nothing but what SIGKILL leaves (docs/cli.md, "Signals").
// SIGINT, SIGTERM and SIGHUP are blocked in every thread and taken by one thread with sigwait, so
// the cleanup runs as ordinary code (it removes folder trees, which a signal handler may not do):
// it kills the child process groups of `verify --cmd`, removes the registered temporaries
// (io/atomic_file.hpp) and exits with 128 + the signal's number.

#include <pthread.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <thread>

#include "common.hpp"
#include "atomic_file.hpp"

namespace cmc33::cli {

namespace {

const char* signal_text(int sig)
{
    switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
    }
}

} // namespace

void install_signal_cleanup()
{
    sigset_t set;
    sigemptyset(&set);
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&set, sig);
    // Before any other thread exists: the threads started later inherit the mask.
    if (::pthread_sigmask(SIG_BLOCK, &set, nullptr) != 0) return;
    std::thread([set] {
        int sig = 0;
        while (::sigwait(&set, &sig) != 0) {
        }
        const int removed = io::detail::remove_temporaries();
        char line[128];
        if (removed == 0) {
            std::snprintf(line, sizeof line, "cmc33: interrupted by %s\n", signal_text(sig));
        } else {
            std::snprintf(line, sizeof line, "cmc33: interrupted by %s; removed %d temporary %s\n", signal_text(sig),
                          removed, removed == 1 ? "file or folder" : "files or folders");
        }
        // stdout is not flushed: a half-printed report is worth less than a prompt exit.
        (void)!::write(STDERR_FILENO, line, std::strlen(line));
        ::_exit(128 + sig);
    }).detach();
}

} // namespace cmc33::cli
