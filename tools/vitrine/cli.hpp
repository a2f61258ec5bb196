#pragma once

#include <map>
#include <string>
#include <vector>

namespace vitrine::cli {

// Parsed command line: positional arguments, repeatable options (--set) and flags.
struct Args {
    std::string command;
    std::vector<std::string> positional;
    std::map<std::string, std::vector<std::string>> options;

    bool has(const std::string& name) const { return options.count(name) != 0; }
    std::string get(const std::string& name, const std::string& fallback = "") const;
    const std::vector<std::string>& all(const std::string& name) const;
    uint32_t getUint(const std::string& name, uint32_t fallback) const;
};

// `valued`: options that take a value (`--out DIR` or `--out=DIR`); everything else starting with -- is a flag.
// `optional`: per command, options whose value may be left out (`nodes --json` prints to stdout, `nodes --json FILE`
// writes FILE): they take the next argument unless it starts with "--" or there is none, and take the value "" then.
// An option named in both is optional for the commands listed and needs its value for every other command
// (`bench --json FILE`).
Args parse(int argc, char** argv, const std::vector<std::string>& valued,
           const std::map<std::string, std::vector<std::string>>& optional = {});

int runCommand(const Args& args);
int validateCommand(const Args& args);
int nodesCommand(const Args& args);
int schemaCommand(const Args& args);
int benchCommand(const Args& args);
int graphCommand(const Args& args);
int devicesCommand(const Args& args);
int compareCommand(const Args& args);
int goldenCommand(const Args& args);
int exportSceneCommand(const Args& args);
int jitterCommand(const Args& args);
int serveCommand(const Args& args);
int sweepCommand(const Args& args);
int cacheCommand(const Args& args);

} // namespace vitrine::cli
