#!/usr/bin/env bash
# Installs every Debian package vitrine needs to build, run and test. Idempotent: packages
# already present are skipped by apt. Needs root (or sudo) on Debian 12 (bookworm).
# --fuzz: also clang and its runtime libraries for tools/fuzz.sh (libFuzzer, ASan, UBSan: on bookworm
# libclang_rt.fuzzer-x86_64.a is in libclang-rt-14-dev, which the libclang-rt-dev package pulls in; clang only
# recommends it, and recommendations are not installed here).
set -euo pipefail

packages=(
    build-essential cmake ninja-build pkg-config git
    libvulkan-dev vulkan-tools mesa-vulkan-drivers vulkan-validationlayers
    glslang-dev glslang-tools spirv-tools
    libglm-dev libtinygltf-dev libstb-dev nlohmann-json3-dev
    libopenexr-dev libimath-dev libopencolorio-dev
    libgtest-dev libgmock-dev libbenchmark-dev
    python3-jsonschema
    libcpp-httplib-dev
    slurmctld slurmd slurm-client munge
)
if [ "${1:-}" = "--fuzz" ]; then
    packages+=(clang libclang-rt-dev)
fi

missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
    echo "install-deps: all ${#packages[@]} packages present"
    exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
