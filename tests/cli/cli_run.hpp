#pragma once
// Running the command-line tool from a test: `cmc33 ARGS` through the shell, stdout through a pipe,
// stderr through a file, and stdout parsed as JSON. Shared by the CLI's test executables, each of
// which defines CMC33_EXE (the tool's path) for itself.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace cmc33::test::cli {

struct Result {
    int code = -1;
    std::string out;
    std::string err;
};

/// `s` as one single-quoted shell word.
inline std::string quote(const std::string& s)
{
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

/// Runs `cmc33 ARGS` through the shell: stdout through a pipe, stderr through a file, no standard
/// input. `shell` comes before the command on the same line ("cd DIR && ", "ulimit -f 1; exec ").
inline Result run(const std::string& args, const std::string& shell = "")
{
    namespace fs = std::filesystem;
    static int counter = 0;
    const fs::path err_file = fs::temp_directory_path() /
                              ("cmc33-cli-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".err");
    const std::string command =
        "{ " + shell + quote(CMC33_EXE) + " " + args + "; } 2>" + quote(err_file.string()) + " </dev/null";
    Result r;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) {
        ADD_FAILURE() << "popen failed for " << command;
        return r;
    }
    char buffer[4096];
    std::size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) r.out.append(buffer, n);
    const int status = ::pclose(pipe);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.err = test::read_file(err_file);
    fs::remove(err_file);
    return r;
}

/// Parses stdout as one JSON value; a failure is reported with the text (and an empty object).
inline nlohmann::json parse(const Result& r)
{
    try {
        return nlohmann::json::parse(r.out);
    } catch (const std::exception& e) {
        ADD_FAILURE() << "stdout is not JSON (" << e.what() << "):\n" << r.out << r.err;
        return nlohmann::json::object();
    }
}

/// The usage-error contract: exit 2, "cmc33: ..." on stderr pointing to --help, nothing on stdout.
inline void expect_usage_error(const Result& r)
{
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("cmc33: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("--help"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
}

/// expect_usage_error, and the message on one line containing every one of `parts`, then the --help line.
inline void expect_usage_error(const Result& r, const std::vector<std::string>& parts)
{
    expect_usage_error(r);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
    const std::string first = r.err.substr(0, r.err.find('\n'));
    for (const std::string& part : parts)
        EXPECT_NE(first.find(part), std::string::npos) << "no '" << part << "' in " << r.err;
}

/// The error contract: exit 1, one line "cmc33: ..." on stderr containing every one of `parts`,
/// nothing on stdout.
inline void expect_failure(const Result& r, const std::vector<std::string>& parts)
{
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(r.err.rfind("cmc33: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    for (const std::string& part : parts)
        EXPECT_NE(r.err.find(part), std::string::npos) << "no '" << part << "' in " << r.err;
    EXPECT_EQ(r.out, "");
}

/// The names of the entries of `dir`, sorted.
inline std::vector<std::string> files_in(const std::filesystem::path& dir)
{
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

/// 8^3 uint8 samples of a ball: meshes to a closed surface at iso 100.
inline std::string ball_samples()
{
    std::string bytes;
    for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) {
                const double x = i - 3.5, y = j - 3.5, z = k - 3.5;
                bytes += static_cast<char>(x * x + y * y + z * z < 9 ? 200 : 0);
            }
    return bytes;
}

} // namespace cmc33::test::cli
