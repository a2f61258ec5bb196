#!/usr/bin/env bash
# Installs the Debian packages (tools/install-deps.sh) and builds vitrine into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
# ccache (installed by install-deps) makes a second build of the same sources cheap, also from another clone:
# paths are hashed relative to the checkout and the working directory is left out of the hash.
launcher=()
if command -v ccache >/dev/null; then
    export CCACHE_BASEDIR="$(pwd)" CCACHE_NOHASHDIR=1
    launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
# Line tables only (-g1): backtraces and profiles keep file:line, and the cold build takes about a third less time
# than with full debug info on 2 cores. Full debug info: bash tools/build.sh -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g -DNDEBUG"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" "$@"
cmake --build build -j "$(nproc)"
