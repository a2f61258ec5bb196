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

# The Khronos glTF-Validator for ctest gltf.validator (tests/gltf/check_validator.py): npm gltf-validator exactly as
# tools/gltf-validator/package-lock.json pins it, installed the same way, only when the lockfile changed.
validator="$(dirname "$0")/gltf-validator"
if [ -f "$validator/package-lock.json" ]; then
    want="$(sha256sum < "$validator/package-lock.json" | cut -d' ' -f1) node $(node --version)"
    stamp="$validator/node_modules/.vitrine-install-stamp"
    if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
        echo "install-deps: tools/gltf-validator/node_modules is current"
    else
        echo "install-deps: npm ci in tools/gltf-validator/ (from package-lock.json)"
        (cd "$validator" && npm ci --no-audit --no-fund)
        echo "$want" > "$stamp"
    fi
fi

# The Khronos glTF Sample Viewer's engine for ctest gltf.sample_viewer (tests/viewer/): npm @khronosgroup/gltf-viewer
# exactly as tools/gltf-viewer/package-lock.json pins it, installed the same way, only when the lockfile changed. It runs
# in the chromium installed above (driven by editor/node_modules/playwright-core); it downloads nothing itself.
viewer="$(dirname "$0")/gltf-viewer"
if [ -f "$viewer/package-lock.json" ]; then
    want="$(sha256sum < "$viewer/package-lock.json" | cut -d' ' -f1) node $(node --version)"
    stamp="$viewer/node_modules/.vitrine-install-stamp"
    if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
        echo "install-deps: tools/gltf-viewer/node_modules is current"
    else
        echo "install-deps: npm ci in tools/gltf-viewer/ (from package-lock.json)"
        (cd "$viewer" && npm ci --no-audit --no-fund)
        echo "$want" > "$stamp"
    fi
fi
