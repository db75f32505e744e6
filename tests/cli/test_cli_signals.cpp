// The real `cmc33` executable (CMC33_EXE) stopped by signals, and `cmc33 verify` with external
// tools that hang or are interrupted: nothing left behind, no tool left running.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cmc33/io.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace cmc33 {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::cli::expect_failure;
using test::cli::expect_usage_error;
using test::cli::files_in;
using test::cli::parse;
using test::cli::quote;
using test::cli::Result;
using test::cli::run;

// ---- reliability: signals ------------------------------------------------------------------------

/// A child cmc33 started without a shell, so that a signal goes to it alone.
struct Child {
    pid_t pid = -1;
    fs::path err;
};

Child spawn(const std::vector<std::string>& args, const fs::path& err, const std::vector<std::string>& env = {})
{
    std::vector<std::string> all{CMC33_EXE};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> environment = env;
    for (char** e = environ; *e != nullptr; ++e) environment.emplace_back(*e);
    std::vector<char*> envp;
    for (std::string& e : environment) envp.push_back(e.data());
    envp.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    Child c;
    c.err = err;
    if (::posix_spawn(&c.pid, argv[0], &actions, nullptr, argv.data(), envp.data()) != 0) c.pid = -1;
    posix_spawn_file_actions_destroy(&actions);
    return c;
}

/// Waits up to `seconds` for `ready` (polled every millisecond) while the child runs; false if
/// the child ended or the time ran out.
template <class Ready> bool wait_until(const Child& c, double seconds, Ready&& ready)
{
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
        if (ready()) return true;
        int status = 0;
        if (::waitpid(c.pid, &status, WNOHANG) == c.pid) {
            ADD_FAILURE() << "the child ended (status " << status << ") before it was ready";
            return false;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ADD_FAILURE() << "not ready after " << seconds << " s";
    return false;
}

/// The exit code (or -1 if killed) of a child, waited for at most 60 s.
int exit_code(const Child& c)
{
    for (int i = 0; i < 6000; ++i) {
        int status = 0;
        if (::waitpid(c.pid, &status, WNOHANG) == c.pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::kill(c.pid, SIGKILL);
    ::waitpid(c.pid, nullptr, 0);
    ADD_FAILURE() << "the child did not exit within 60 s of the signal";
    return -1;
}

std::optional<fs::path> hidden_temporary(const fs::path& dir, const std::string& prefix)
{
    for (const auto& e : fs::directory_iterator(dir)) {
        if (e.path().filename().string().rfind(prefix, 0) == 0) return e.path();
    }
    return std::nullopt;
}

/// A gyroid-like field with a surface in almost every cell: millions of triangles, whose OBJ
/// takes long enough to write (about 190 MB) that a signal arrives while the temporary exists.
fs::path write_busy_volume(const fs::path& dir)
{
    const fs::path path = dir / "busy.nrrd";
    const Volume v = test::make_volume({160, 160, 160}, [](std::int64_t i, std::int64_t j, std::int64_t k) {
        const double x = 0.9 * static_cast<double>(i), y = 0.9 * static_cast<double>(j), z = 0.9 * static_cast<double>(k);
        return std::sin(x) * std::cos(y) + std::sin(y) * std::cos(z) + std::sin(z) * std::cos(x);
    });
    io::write_volume(v, path);
    return path;
}

TEST(CliSignals, InterruptedExtractRemovesItsTemporaryFile)
{
    const fs::path dir = test::temp_dir();
    const fs::path volume = write_busy_volume(dir);
    for (const auto& [sig, name] : std::vector<std::pair<int, std::string>>{
             {SIGINT, "SIGINT"}, {SIGTERM, "SIGTERM"}, {SIGHUP, "SIGHUP"}}) {
        SCOPED_TRACE(name);
        const Child c = spawn({"extract", volume.string(), "--iso", "0.1", "-o", (dir / "big.obj").string(), "--no-topology"},
                              dir / "err.txt");
        ASSERT_GT(c.pid, 0);
        std::optional<fs::path> temp;
        ASSERT_TRUE(wait_until(c, 60, [&] { return (temp = hidden_temporary(dir, ".big.obj.tmp")).has_value(); }));
        EXPECT_NE(temp->filename().string().find(".tmp" + std::to_string(c.pid) + "-"), std::string::npos) << *temp;
        ::kill(c.pid, sig);
        EXPECT_EQ(exit_code(c), 128 + sig);
        const std::string err = test::read_file(dir / "err.txt");
        EXPECT_EQ(err, "cmc33: interrupted by " + name + "; removed 1 temporary file or folder\n");
        EXPECT_EQ(files_in(dir), (std::vector<std::string>{"busy.nrrd", "err.txt"}));
    }
}

/// True once `pid` is gone or a zombie (an orphan whose reaper has not come yet).
bool dead(pid_t pid)
{
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string text;
    if (!std::getline(stat, text)) return true;
    const std::size_t paren = text.rfind(')');
    return paren != std::string::npos && paren + 2 < text.size() && text[paren + 2] == 'Z';
}

TEST(CliSignals, InterruptedVerifyKillsTheToolAndRemovesItsFolder)
{
    const fs::path dir = test::temp_dir();
    const fs::path ds = dir / "ds";
    ASSERT_EQ(run("dataset " + quote(ds.string()) + " --cells 4 --grids 0 --closed 0").code, 0);
    const fs::path tmp = dir / "tmp";
    fs::create_directory(tmp);
    const fs::path pid_file = dir / "tool.pid";
    // The tool writes its pid (that of its process group's shell) and hangs.
    const std::string tool = "echo $$ > " + quote(pid_file.string()) + "; sleep 60; true {in} {out}";
    const Child c = spawn({"verify", "--dataset", ds.string(), "--cmd", tool, "--threads", "1"}, dir / "err.txt",
                          {"TMPDIR=" + tmp.string()});
    ASSERT_GT(c.pid, 0);
    ASSERT_TRUE(wait_until(c, 30, [&] { return !test::read_file(pid_file).empty(); }));
    const pid_t tool_pid = std::stoi(test::read_file(pid_file));
    const std::optional<fs::path> folder = hidden_temporary(tmp, "cmc33-verify-" + std::to_string(c.pid) + "-");
    ASSERT_TRUE(folder.has_value());
    ::kill(c.pid, SIGTERM);
    EXPECT_EQ(exit_code(c), 143);
    EXPECT_EQ(test::read_file(dir / "err.txt"), "cmc33: interrupted by SIGTERM; removed 1 temporary file or folder\n");
    EXPECT_TRUE(fs::is_empty(tmp));
    for (int i = 0; i < 200 && !dead(tool_pid); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_TRUE(dead(tool_pid)) << "the tool's process group was not killed";
}

// ---- reliability: verify -------------------------------------------------------------------------

TEST(CliVerify, DefaultIsCmc33AloneAndWritesNoFailuresFolder)
{
    const fs::path dir = test::temp_dir();
    const std::string here = "cd " + quote(dir.string()) + " && ";
    const Result r = run("verify --cells 3000 --grids 300 --closed 100 --json", here);
    ASSERT_EQ(r.code, 0) << r.err;
    json j = parse(r);
    ASSERT_EQ(j["methods"].size(), 1u);
    EXPECT_EQ(j["methods"][0]["method"], "cmc33");
    EXPECT_TRUE(j["failures"].is_null());

    // The legacy methods when asked for: they fail, and still write nothing unless told where.
    const Result legacy = run("verify --cells 2000 --method mc,mc33-lewiner", here);
    EXPECT_EQ(legacy.code, 1);
    EXPECT_EQ(std::count(legacy.err.begin(), legacy.err.end(), '\n'), 2) << legacy.err; // progress + message
    EXPECT_NE(legacy.err.find("rerun with --failures DIR"), std::string::npos) << legacy.err;
    EXPECT_TRUE(fs::is_empty(dir)) << "verify wrote into the current folder";

    const Result all = run("verify --cells 2000 --methods all --max-failures 2 --json --failures " +
                           quote((dir / "failed").string()));
    EXPECT_EQ(all.code, 1);
    j = parse(all);
    ASSERT_EQ(j["methods"].size(), 5u); // cmc33, cmc33-paper, chernyaev, mc33-lewiner, mc
    EXPECT_EQ(j["failures"]["dir"], (dir / "failed").string());
    EXPECT_TRUE(fs::exists(dir / "failed" / "failures.tsv"));
    EXPECT_NE(all.err.find("failures in " + (dir / "failed").string()), std::string::npos) << all.err;
    // The older spelling still works.
    EXPECT_EQ(run("verify --cells 200 --method cmc33 --method mc33-lewiner --json").code, 1);
    expect_usage_error(run("verify --cells 5 --method all --method mc"), {"--method all"});
    expect_usage_error(run("verify --cells 5 --method marching"), {"--method"});
    // Failures cannot go into a file, or into the dataset checked.
    test::write_file(dir / "file", "x");
    expect_failure(run("verify --cells 5 --failures " + quote((dir / "file").string())), {"not a folder"});
}

TEST(CliVerify, TimeoutKillsAHangingToolAndGoesOn)
{
    const fs::path dir = test::temp_dir();
    const fs::path ds = dir / "ds";
    ASSERT_EQ(run("dataset " + quote(ds.string()) + " --cells 3 --grids 0 --closed 0").code, 0);
    const auto start = std::chrono::steady_clock::now();
    const Result r = run("verify --dataset " + quote(ds.string()) +
                         " --cmd 'sleep 60; true {in} {out}' --timeout 0.5 --threads 3 --json");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 30);
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err; // progress line + the message
    EXPECT_NE(r.err.find("cmc33: verify: command 3 mismatched"), std::string::npos) << r.err;
    const json j = parse(r);
    EXPECT_EQ(j["methods"][0]["errors"], 3);
    EXPECT_NE(j["methods"][0]["first_error"].get<std::string>().find("did not finish within 0.5 s (--timeout)"),
              std::string::npos)
        << j["methods"][0]["first_error"];
    const Result text = run("verify --dataset " + quote(ds.string()) + " --cmd 'sleep 60; true {in} {out}' --timeout 0.2");
    EXPECT_NE(text.out.find("command: 3 fields gave no mesh; the first, cell-000001: the command did not finish"),
              std::string::npos)
        << text.out;
    expect_usage_error(run("verify --cells 5 --timeout 3"), {"--timeout"});
    for (const char* bad : {"0", "-1", "''", "abc"}) {
        expect_usage_error(run("verify --dataset " + quote(ds.string()) + " --cmd 'true {in} {out}' --timeout " + bad),
                           {"--timeout"});
    }
}

} // namespace
} // namespace cmc33
