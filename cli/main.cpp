// cmc33: the command-line tool. Parses the line with CLI11, runs the one command given, and maps
// every failure to one line on stderr and an exit code:
//   0 success; 1 bad input or failure (cmc33::Error, unreadable file, non-finite sample, ...);
//   2 bad usage (CLI11's parse errors and the commands' UsageError);
//   128 + N killed by signal N among SIGINT (130), SIGTERM (143), SIGHUP (129), after removing
//   its temporary files (cli/signals.cpp).

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "cmc33/error.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/version.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "portability.hpp"

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

/// glibc's malloc keeps what the tool frees for its next step instead of unmapping it: blocks up
/// to 32 MiB (its largest mmap threshold) come from the heap, and freed heap memory is not
/// trimmed, so that the check, the writers and the label surfaces reuse pages the extraction
/// touched rather than fault in fresh ones (costly on a VM, the more so where a balloon takes
/// free pages back). Blocks over 16 MiB of meshes are Buffer's (src/base/buffer.cpp) and keep
/// their own cache; the slab engine still trims after each slab (--memory-limit).
void keep_freed_memory()
{
#if defined(__GLIBC__)
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

/// One line: messages from files may hold newlines (a quoted header line), the contract is one line.
std::string one_line(std::string message)
{
    for (char& c : message) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    return message;
}

int fail(const std::string& message)
{
    std::cout.flush();
    std::cerr << "cmc33: " << one_line(message) << '\n';
    return kExitFailure;
}

int usage(const std::string& message)
{
    std::cout.flush();
    std::cerr << "cmc33: " << one_line(message) << '\n' << "Run with --help for more information.\n";
    return kExitUsage;
}

/// CLI11 reads "-5" as a value (no option is named -5) but "-.5" as the short option '.'; spell
/// such numbers "-0.5" so that `cmc33 cell -.5 ...` means what it says.
std::vector<std::string> arguments(int argc, char** argv)
{
    std::vector<std::string> args;
    for (int i = argc - 1; i >= 1; --i) { // CLI11 takes them in reverse order
        std::string a = argv[i];
        if (a.size() >= 3 && a[0] == '-' && a[1] == '.' && a[2] >= '0' && a[2] <= '9') a.insert(1, "0");
        args.push_back(std::move(a));
    }
    return args;
}

/// Whether `token` names an option of `cmd` (or of the whole tool): "--name", "--name=value",
/// "-n" or "-nVALUE" (a short option with its value attached).
bool known_option(const CLI::App& app, const CLI::App* cmd, const std::string& token)
{
    std::string name = token.substr(0, token.find('='));
    if (name.size() > 2 && name[1] != '-') name.resize(2); // -nVALUE
    for (const CLI::App* a : {cmd, &app}) {
        if (a == nullptr) continue;
        for (const CLI::Option* o : a->get_options()) {
            if (o->check_name(name)) return true;
        }
    }
    return false;
}

struct DashFile {
    std::string command; ///< the subcommand given, or "COMMAND"
    std::string file;    ///< empty: none
};

/// The first argument that starts with '-' but is neither an option nor a number, before any "--":
/// a file named "-x.nrrd", which CLI11 takes for an unknown option (then reports "INPUT is required").
DashFile dash_file(CLI::App& app, const std::vector<std::string>& args)
{
    const CLI::App* cmd = nullptr;
    for (auto it = args.rbegin(); it != args.rend(); ++it) { // args are reversed
        const std::string& a = *it;
        if (a == "--") break;
        if (cmd == nullptr && !a.empty() && a[0] != '-') {
            for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
                if (sub->get_name() == a) cmd = sub;
            }
        }
        if (a.size() < 2 || a[0] != '-') continue;
        char* end = nullptr;
        (void)std::strtod(a.c_str(), &end);
        if (end != nullptr && *end == '\0') continue; // a negative number, a value
        if (!known_option(app, cmd, a)) return {cmd ? cmd->get_name() : "COMMAND", a};
    }
    return {};
}

} // namespace

int main(int argc, char** argv)
{
    cmc33::cli::install_signal_cleanup(); // first: every thread started later inherits its signal mask
    keep_freed_memory();
    // a new huge page costs more than it saves where the VM's balloon takes free memory back
    cmc33::set_huge_page_advice(!cmc33::detail::balloon_reports_free_memory());
    CLI::App app("cmc33 " CMC33_VERSION_STRING ": extracts a topologically correct, manifold isosurface mesh\n"
                 "from a 3D scalar volume with Marching Cubes 33 (Custodio et al. 2013), and inspects\n"
                 "volumes, meshes and single cells.",
                 "cmc33");
    app.set_version_flag("--version", "cmc33 " CMC33_VERSION_STRING, "Print the version and exit");
    app.require_subcommand(1);
    app.allow_extras(false);
    app.footer("Run `cmc33 COMMAND --help` for a command's options and an example.\n"
               "Exit codes: 0 success, 1 bad input or failure, 2 bad usage,\n"
               "130/143/129 interrupted by SIGINT/SIGTERM/SIGHUP (temporary files removed).\n"
               "Example:\n"
               "  cmc33 extract head.nrrd --iso 80 -o head.ply");
    app.get_formatter()->column_width(36);
    for (const cmc33::cli::AddCommand add : cmc33::cli::kCommands) add(app);

    try {
        std::vector<std::string> args = arguments(argc, argv);
        if (!args.empty() && !args.back().empty() && args.back()[0] != '-') {
            // CLI11 would only say "A subcommand is required".
            std::string known;
            bool found = false;
            for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
                known += (known.empty() ? "" : ", ") + sub->get_name();
                found = found || sub->get_name() == args.back();
            }
            if (!found) return usage("unknown command '" + args.back() + "'; the commands are " + known);
        }
        const std::vector<std::string> given = args; // parse() consumes args
        try {
            app.parse(args);
        } catch (const CLI::CallForHelp& e) {
            return app.exit(e);
        } catch (const CLI::CallForAllHelp& e) {
            return app.exit(e);
        } catch (const CLI::CallForVersion& e) {
            return app.exit(e);
        } catch (const CLI::ParseError& e) {
            const DashFile dash = dash_file(app, given);
            if (!dash.file.empty() && (dynamic_cast<const CLI::RequiredError*>(&e) || dynamic_cast<const CLI::ExtrasError*>(&e))) {
                return usage(dash.file + " is not an option of cmc33 " + dash.command + "; if it is a file, put it after " +
                             "\"--\", the options before it (cmc33 " + dash.command + " [OPTIONS] -- " + dash.file +
                             "), or write it ./" + dash.file);
            }
            return usage(e.what());
        }
        std::cout.flush();
        if (!std::cout) return fail("cannot write to standard output");
        return 0;
    } catch (const cmc33::cli::UsageError& e) {
        return usage(e.what());
    } catch (const cmc33::Error& e) {
        return fail(e.what());
    } catch (const std::bad_alloc&) {
        return fail("out of memory");
    } catch (const std::exception& e) {
        return fail(e.what());
    } catch (...) {
        return fail("unknown error");
    }
}
