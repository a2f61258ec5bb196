#include "core/base/paths.hpp"

#include "core/base/error.hpp"

#include <dlfcn.h>

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

// The shared object this code was linked into when it is not the program: the Python module (tools/python/), loaded
// by python3. Empty in the vitrine binary.
fs::path loadedModule() {
    Dl_info info{};
    if (!dladdr(reinterpret_cast<const void*>(&loadedModule), &info) || !info.dli_fname) return {};
    std::error_code ec;
    fs::path module = fs::canonical(info.dli_fname, ec);
    if (ec || module.extension() != ".so") return {};
    return module;
}

Root findRoot() {
    std::error_code ec;
    // The Python module: installed as P/lib/python3/dist-packages/vitrine*.so next to P/share/vitrine; in the build
    // tree it reads the source tree (never the share/ of whatever python3 program loaded it).
    const fs::path module = loadedModule();
    fs::path share;
    if (!module.empty()) {
        if (module.parent_path().filename().string().ends_with("-packages")) {
            share = module.parent_path().parent_path().parent_path().parent_path() / "share" / "vitrine";
            if (fs::is_directory(share / "shaders", ec)) return {share.lexically_normal(), true};
        }
    } else if (const fs::path exe = fs::read_symlink("/proc/self/exe", ec); !ec) {
        share = exe.parent_path().parent_path() / "share" / "vitrine";
        if (fs::is_directory(share / "shaders", ec)) return {share.lexically_normal(), true};
    }
    const char* off = std::getenv("VITRINE_NO_SOURCE_TREE");
    if (off && *off && std::strcmp(off, "0") != 0)
        throw UserError(std::string(module.empty() ? "no installed shaders next to the vitrine binary"
                                                   : "no installed shaders next to the vitrine Python module") +
                        " (expected " +
                        (share.empty() ? std::string("<prefix>/share/vitrine/shaders") : (share / "shaders").string()) +
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
