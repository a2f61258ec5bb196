#pragma once
// Running the `vitrine` program from GPU tests (the CLI, compare and --scene tests): shell quoting, the run
// itself with its exit status and merged output, and scratch folders under the build tree.
#include <filesystem>
#include <string>

namespace vitrine::test {

// `s` single-quoted for the shell.
std::string quote(const std::string& s);

struct CliResult {
    int status = -1;    // exit status, or -1 when the program did not exit normally
    int signal = 0;     // the signal that ended it, if one did
    std::string output; // stdout and stderr
};

// Runs `ENV vitrine ARGS` (VITRINE_BINARY) through the shell with stderr merged into stdout.
CliResult vitrine(const std::string& args, const std::string& env = "");

// A fresh, empty folder `name` under the build tree's test output (VITRINE_TEST_OUT).
std::filesystem::path freshDir(const std::string& name);

// A whole file as bytes in a string (empty when it cannot be read).
std::string readFile(const std::filesystem::path& path);

} // namespace vitrine::test
