// `vitrine cache ls` and `vitrine cache rm NAME... | --all`: the bake cache (core/bake/cache.hpp) as a user sees it,
// every entry with its kind, size and age, and removing entries by the names `ls` prints. Nothing outside the cache's
// bake folder is ever removed: a name that leads out of it (absolute, "..", a symbolic link) is refused.
#include "core/bake/cache.hpp"
#include "core/base/error.hpp"
#include "core/shader/compiler.hpp"
#include "tools/vitrine/cli.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace vitrine::cli {

namespace fs = std::filesystem;

namespace {

std::string formatBytes(uint64_t bytes) {
    char buffer[32];
    if (bytes < 1024)
        std::snprintf(buffer, sizeof buffer, "%llu B", static_cast<unsigned long long>(bytes));
    else if (bytes < (1ull << 20))
        std::snprintf(buffer, sizeof buffer, "%.1f KiB", bytes / 1024.0);
    else if (bytes < (1ull << 30))
        std::snprintf(buffer, sizeof buffer, "%.1f MiB", bytes / double(1ull << 20));
    else
        std::snprintf(buffer, sizeof buffer, "%.2f GiB", bytes / double(1ull << 30));
    return buffer;
}

std::string formatAge(fs::file_time_type modified) {
    const auto seconds =
        std::chrono::duration_cast<std::chrono::seconds>(fs::file_time_type::clock::now() - modified).count();
    char buffer[32];
    if (seconds < 0)
        std::snprintf(buffer, sizeof buffer, "in the future");
    else if (seconds < 120)
        std::snprintf(buffer, sizeof buffer, "%lld s", static_cast<long long>(seconds));
    else if (seconds < 2 * 3600)
        std::snprintf(buffer, sizeof buffer, "%lld min", static_cast<long long>(seconds / 60));
    else if (seconds < 2 * 86400)
        std::snprintf(buffer, sizeof buffer, "%lld h", static_cast<long long>(seconds / 3600));
    else
        std::snprintf(buffer, sizeof buffer, "%lld d", static_cast<long long>(seconds / 86400));
    return buffer;
}

int listEntries(const BakeCache& cache) {
    const std::vector<BakeEntry> entries = cache.list();
    std::printf("bake cache: %s\n", cache.dir().string().c_str());
    if (entries.empty()) {
        std::printf("no entries\n");
        return 0;
    }
    std::printf("%-12s %10s %8s  %s\n", "KIND", "SIZE", "AGE", "NAME");
    uint64_t total = 0;
    for (const BakeEntry& e : entries) {
        total += e.bytes;
        std::printf("%-12s %10s %8s  %s%s\n", e.kind.empty() ? "?" : e.kind.c_str(), formatBytes(e.bytes).c_str(),
                    formatAge(e.modified).c_str(), e.name.c_str(),
                    e.problem.empty() ? "" : ("  (" + e.problem + ")").c_str());
    }
    std::printf("%zu entr%s, %s in all\n", entries.size(), entries.size() == 1 ? "y" : "ies",
                formatBytes(total).c_str());
    return 0;
}

// `name` as `ls` prints it (KIND/FILE) or a kind folder, refused when it leads outside the cache folder.
fs::path resolveName(const BakeCache& cache, const std::string& name) {
    const std::string expected = "expected a NAME as `vitrine cache ls` prints it (KIND/HASH.bin) or a KIND";
    const fs::path relative(name);
    bool upward = false;
    for (const fs::path& part : relative)
        upward |= part == "..";
    if (name.empty() || relative.is_absolute() || upward)
        throw UserError("cache rm '" + name + "': outside the bake cache " + cache.dir().string() + "; " + expected);
    std::error_code ec;
    const fs::path root = fs::weakly_canonical(cache.dir(), ec);
    const fs::path target = fs::weakly_canonical(cache.dir() / relative, ec);
    const fs::path inside = target.lexically_relative(root);
    if (ec || inside.empty() || *inside.begin() == ".." || inside == ".")
        throw UserError("cache rm '" + name + "': leads outside the bake cache " + cache.dir().string() +
                        " (a symbolic link?); " + expected);
    if (!fs::exists(fs::symlink_status(cache.dir() / relative, ec)))
        throw UserError("cache rm '" + name + "': no such entry in " + cache.dir().string() + "; " + expected);
    return (cache.dir() / relative).lexically_normal();
}

int removeEntries(const BakeCache& cache, const Args& args) {
    const bool all = args.has("all");
    const std::vector<std::string>& names = args.positional;
    if (all == (names.size() > 1))
        throw UserError("cache rm: expected NAME... (as `vitrine cache ls` prints them) or --all, not " +
                        std::string(all ? "both" : "neither"));
    const std::vector<BakeEntry> entries = cache.list();
    std::vector<const BakeEntry*> chosen;
    if (all) {
        for (const BakeEntry& e : entries)
            chosen.push_back(&e);
    } else {
        // Every name is checked before anything is removed.
        std::vector<fs::path> targets;
        for (size_t i = 1; i < names.size(); ++i)
            targets.push_back(resolveName(cache, names[i]));
        for (const BakeEntry& e : entries)
            for (const fs::path& t : targets) {
                const fs::path inside = e.path.lexically_relative(t);
                if (e.path == t || (!inside.empty() && *inside.begin() != "..")) {
                    chosen.push_back(&e);
                    break;
                }
            }
    }
    uint64_t total = 0;
    size_t removed = 0;
    for (const BakeEntry* e : chosen) {
        std::error_code ec;
        if (!fs::remove(e->path, ec) || ec) {
            std::fprintf(stderr, "could not remove %s: %s\n", e->path.string().c_str(),
                         ec ? ec.message().c_str() : "already gone");
            continue;
        }
        std::printf("removed %s (%s)\n", e->name.c_str(), formatBytes(e->bytes).c_str());
        total += e->bytes;
        ++removed;
    }
    // Kind folders left empty go too (only folders inside the cache, only when empty).
    std::error_code ec;
    if (fs::is_directory(cache.dir(), ec))
        for (const fs::directory_entry& d : fs::directory_iterator(cache.dir(), ec))
            if (d.is_directory(ec) && !d.is_symlink(ec) && fs::is_empty(d.path(), ec)) fs::remove(d.path(), ec);
    std::printf("removed %zu entr%s, %s from %s\n", removed, removed == 1 ? "y" : "ies", formatBytes(total).c_str(),
                cache.dir().string().c_str());
    return removed == chosen.size() ? 0 : 2;
}

} // namespace

int cacheCommand(const Args& args) {
    const std::string usage = "expected `vitrine cache ls` or `vitrine cache rm NAME...|--all`";
    if (args.positional.empty()) throw UserError("cache: " + usage);
    const BakeCache cache(defaultCacheDir());
    const std::string& sub = args.positional[0];
    if (sub == "ls") {
        if (args.positional.size() > 1) throw UserError("cache ls: takes no arguments; " + usage);
        return listEntries(cache);
    }
    if (sub == "rm") return removeEntries(cache, args);
    throw UserError("cache: unknown subcommand '" + sub + "'; " + usage);
}

} // namespace vitrine::cli
