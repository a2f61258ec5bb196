#pragma once

#include <filesystem>

namespace vitrine {

// Where vitrine's shared files live: shaders/, data/ (OCIO config, LUTs, lenses, models), graphs/, editor/dist/.
//
// An installed vitrine (`cmake --install build --prefix P`: P/bin/vitrine and P/share/vitrine/...) finds them next to
// itself, through /proc/self/exe: <dir of the binary>/../share/vitrine when that folder holds shaders/. The installed
// Python module (P/lib/python3/dist-packages/vitrine*.so) finds P/share/vitrine the same way from its own file. Otherwise the
// binary is the one in the build tree and they are the source tree's (the path compiled in at configure time).
// With VITRINE_NO_SOURCE_TREE=1 in the environment that fallback is off: a binary that is not installed then fails
// with a clear error instead of reading the source tree (the install test runs the installed copy with it).
std::filesystem::path resourceRoot();
// resourceRoot() is an installed share/vitrine (not the source tree).
bool runningInstalled();
// $VITRINE_SHADER_DIR, else resourceRoot()/shaders.
std::filesystem::path shaderDir();
// resourceRoot()/data.
std::filesystem::path dataDir();
// $VITRINE_CACHE_DIR, else $XDG_CACHE_HOME/vitrine, else ~/.cache/vitrine: SPIR-V, bakes and the Vulkan pipeline cache.
std::filesystem::path cacheDir();

} // namespace vitrine
