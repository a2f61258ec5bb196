#!/usr/bin/env bash
# The README's first command: install, build, render the Museum graph (graphs/museum.json) headless
# to out/default/. Extra arguments go to `vitrine run` (e.g. --set frame.width=1280).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
./build/vitrine run graphs/museum.json --out out/default "${@}"
echo "images in out/default/"
