#!/usr/bin/env bash
# The README's test command: install, build, run every test (CPU and GPU tiers; the GPU tier
# runs on lavapipe when there is no GPU) with Vulkan validation on.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
vulkaninfo --summary 2>/dev/null | grep -E "deviceName|driverName" || true
ctest --test-dir build --output-on-failure --no-tests=error -j "$(nproc)" --timeout 600
