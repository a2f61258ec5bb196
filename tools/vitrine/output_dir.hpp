#pragma once

#include "core/base/error.hpp"

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

namespace vitrine::cli {

// Files vitrine wrote into an output directory, listed in DIR/.vitrine-outputs. A file that exists but is not listed
// was not written by vitrine, and is not overwritten unless the user passed --overwrite (or --force). Used by `run`,
// `compare` and `golden check`.
class OutputDir {
public:
    OutputDir(std::filesystem::path dir, bool overwrite) : mDir(std::move(dir)), mOverwrite(overwrite) {
        std::error_code ec;
        std::filesystem::create_directories(mDir, ec);
        if (!std::filesystem::is_directory(mDir))
            throw UserError(mDir.string() + ": cannot create the output directory");
        std::ifstream in(mDir / kManifest);
        for (std::string line; std::getline(in, line);)
            if (!line.empty()) mWritten.insert(line);
    }
    // Throws UserError when `name` exists and vitrine did not write it; records it as vitrine's otherwise.
    std::filesystem::path claim(const std::string& name) {
        std::filesystem::path p = mDir / name;
        std::error_code ec;
        std::filesystem::create_directories(p.parent_path(), ec);
        if (std::filesystem::exists(p) && !mWritten.count(name) && !mOverwrite)
            throw UserError(p.string() + ": exists and was not written by vitrine; pass --overwrite (or --force) to "
                                         "replace it, or choose another --out");
        if (mWritten.insert(name).second) std::ofstream(mDir / kManifest, std::ios::app) << name << "\n";
        return p;
    }
    const std::filesystem::path& dir() const { return mDir; }

private:
    static constexpr const char* kManifest = ".vitrine-outputs";
    std::filesystem::path mDir;
    bool mOverwrite;
    std::set<std::string> mWritten;
};

} // namespace vitrine::cli
