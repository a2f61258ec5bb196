#include "core/base/paths.hpp"

#include "core/base/error.hpp"

#include <cstdlib>
#include <cstring>
#include <system_error>

#ifndef VITRINE_SOURCE_DIR
#error "VITRINE_SOURCE_DIR must be defined by the build (see core/CMakeLists.txt)"
#endif

namespace vitrine {

namespace fs = std::filesystem;

namespace {

struct Root {
    fs::path path;
    bool installed = false;
};

Root findRoot() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const fs::path share = exe.parent_path().parent_path() / "share" / "vitrine";
        if (fs::is_directory(share / "shaders", ec)) return {share.lexically_normal(), true};
    }
    const char* off = std::getenv("VITRINE_NO_SOURCE_TREE");
    if (off && *off && std::strcmp(off, "0") != 0)
        throw UserError("no installed shaders next to the vitrine binary (expected " +
                        (ec ? std::string("<prefix>/share/vitrine/shaders") :
                              (exe.parent_path().parent_path() / "share" / "vitrine" / "shaders").string()) +
                        ") and VITRINE_NO_SOURCE_TREE is set, so the source tree " VITRINE_SOURCE_DIR " is not used");
    return {fs::path(VITRINE_SOURCE_DIR), false};
}

const Root& root() {
    static const Root r = findRoot();
    return r;
}

} // namespace

fs::path resourceRoot() { return root().path; }

bool runningInstalled() { return root().installed; }

fs::path shaderDir() {
    if (const char* env = std::getenv("VITRINE_SHADER_DIR"); env && *env) return env;
    return resourceRoot() / "shaders";
}

fs::path dataDir() { return resourceRoot() / "data"; }

fs::path cacheDir() {
    if (const char* env = std::getenv("VITRINE_CACHE_DIR"); env && *env) return env;
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / "vitrine";
    if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "vitrine";
    return fs::temp_directory_path() / "vitrine-cache";
}

} // namespace vitrine
