#!/usr/bin/env bash
# Installs every Debian package vitrine needs to build, run and test. Idempotent: packages
# already present are skipped by apt. Needs root (or sudo) on Debian 12 (bookworm).
# --fuzz: also clang and its runtime libraries for tools/fuzz.sh (libFuzzer, ASan, UBSan: on bookworm
# libclang_rt.fuzzer-x86_64.a is in libclang-rt-14-dev, which the libclang-rt-dev package pulls in; clang only
# recommends it, and recommendations are not installed here).
set -euo pipefail

packages=(
    build-essential cmake ninja-build pkg-config git ccache
    libvulkan-dev vulkan-tools mesa-vulkan-drivers vulkan-validationlayers
    glslang-dev glslang-tools spirv-tools
    libglm-dev libtinygltf-dev libstb-dev nlohmann-json3-dev libembree-dev
    libmeshoptimizer-dev  # glTF's EXT_meshopt_compression
    gltfpack  # tests: an independent EXT_meshopt_compression / KHR_mesh_quantization encoder (tests/unit/scene)
    libopenexr-dev libimath-dev libopencolorio-dev
    libgtest-dev libgmock-dev libbenchmark-dev
    python3-jsonschema
    pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib  # the Python module (tools/python/)
    libcpp-httplib-dev
    dpkg-dev  # dpkg-shlibdeps: the .deb's Depends (cmake/install.cmake)
    slurmctld slurmd slurm-client munge
)
if [ "${1:-}" = "--fuzz" ]; then
    packages+=(clang libclang-rt-dev)
fi
# The graph editor (editor/): its browser tests drive Debian's Chromium (tests/editor/); Node.js >= 18 builds it.
# Debian's nodejs (18.20 on bookworm) and npm only when no node >= 18 is installed (e.g. NodeSource's, which
# bundles npm and conflicts with Debian's npm package).
packages+=(chromium)
if ! node -e 'process.exit(Number(process.versions.node.split(".")[0]) >= 18 ? 0 : 1)' 2>/dev/null; then
    packages+=(nodejs npm)
elif ! command -v npm >/dev/null; then
    packages+=(npm)
fi

missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
    echo "install-deps: all ${#packages[@]} packages present"
else
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
        sudo="sudo"
    fi
    echo "install-deps: installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -qq
    $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}"
fi

# The editor's npm packages, exactly as its committed lockfile pins them (npm ci), only when the lockfile changed
# since the last install (the stamp holds its hash and the node version). Nothing here downloads a browser.
editor="$(dirname "$0")/../editor"
if [ -f "$editor/package-lock.json" ]; then
    want="$(sha256sum < "$editor/package-lock.json" | cut -d' ' -f1) node $(node --version)"
    stamp="$editor/node_modules/.vitrine-install-stamp"
    if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
        echo "install-deps: editor/node_modules is current"
    else
        echo "install-deps: npm ci in editor/ (from package-lock.json)"
        (cd "$editor" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund)
        echo "$want" > "$stamp"
    fi
fi

# npm ci in tools/<dir>/ exactly as its package-lock.json pins it, only when the lockfile (or node) changed.
npm_ci_pinned() {
    local dir="$(dirname "$0")/$1"
    [ -f "$dir/package-lock.json" ] || return 0
    local want stamp="$dir/node_modules/.vitrine-install-stamp"
    want="$(sha256sum < "$dir/package-lock.json" | cut -d' ' -f1) node $(node --version)"
    if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
        echo "install-deps: tools/$1/node_modules is current"
    else
        echo "install-deps: npm ci in tools/$1/ (from package-lock.json)"
        (cd "$dir" && npm ci --no-audit --no-fund)
        echo "$want" > "$stamp"
    fi
}

# The Khronos glTF-Validator for ctest gltf.validator (tests/gltf/check_validator.py).
npm_ci_pinned gltf-validator
# The Khronos glTF Sample Viewer's engine for ctest gltf.sample_viewer (tests/viewer/). It runs in the chromium
# installed above (driven by editor/node_modules/playwright-core); it downloads nothing itself.
npm_ci_pinned gltf-viewer
