#include "tests/gpu/cli.hpp"

#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace vitrine::test {

namespace fs = std::filesystem;

std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s)
        q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

CliResult vitrine(const std::string& args, const std::string& env) {
    const std::string command = env + (env.empty() ? "" : " ") + quote(VITRINE_BINARY) + " " + args + " 2>&1";
    CliResult r;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;)
        r.output.append(buffer, n);
    const int status = pclose(pipe);
    if (WIFEXITED(status)) r.status = WEXITSTATUS(status);
    // The shell reports a child killed by signal N as exit status 128 + N (or is itself replaced by the child).
    if (r.status > 128) r.signal = r.status - 128;
    if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    return r;
}

fs::path freshDir(const std::string& name) {
    const fs::path dir = fs::path(VITRINE_TEST_OUT) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

} // namespace vitrine::test
