#!/usr/bin/env bash
# Opens the graph editor: builds vitrine and the editor's bundle (editor/dist/) when needed, then serves the
# repository root with `vitrine serve .` and prints the URL to open (http://127.0.0.1:8420/?token=... by default:
# the token is what lets the browser in; --no-token drops it).
# Extra arguments go to `vitrine serve` (e.g. --port 0 for any free port). Ctrl-C stops it.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -f build/build.ninja ] || [ -f build/Makefile ]; then
    cmake --build build -j "$(nproc)" --target vitrine $(cmake --build build --target help 2>/dev/null | grep -q '^editor:' && echo editor)
else
    bash tools/build.sh   # first time: installs the Debian and npm packages, configures and builds everything
fi
if [ ! -f editor/dist/index.html ]; then
    echo "tools/editor.sh: editor/dist/ was not built (see the cmake warning; run bash tools/install-deps.sh," \
         "then bash tools/build.sh); serving the API only" >&2
fi
exec ./build/vitrine serve . "$@"
