#!/usr/bin/env bash
# The README's first command: install, build, render the default graph headless to out/.
# Until graphs/museum.json exists (the scene and lighting work), the default graph is the
# FXAA zone plate.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
graph=graphs/museum.json
[ -f "$graph" ] || graph=graphs/fxaa_zoneplate.json
./build/vitrine run "$graph" --out out/default "${@}"
echo "images in out/default/"
