#!/usr/bin/env bash
# ctest install.deb: cpack builds the .deb (DEB generator, cmake/install.cmake); its file list (dpkg-deb -c) must hold
# the binary, shaders, data and graphs under /usr, and its Depends the Debian runtime packages of the linked libraries
# (computed by dpkg-shlibdeps; libvulkan1 stands for them here, as every build links it).
# When the editor is built (SOURCE_DIR/editor/dist/index.html), its bundle must be in the package too.
# Usage: deb_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$(cd "$1" && pwd)"
src="$(cd "$2" && pwd)"
work="$build/deb-test"
rm -rf "$work"
mkdir -p "$work"
fail() { echo "install.deb: FAIL: $*" >&2; exit 1; }

cpack --config "$build/CPackConfig.cmake" -B "$work" > "$work/cpack.log" 2>&1 || { cat "$work/cpack.log" >&2; fail "cpack failed"; }
debs=("$work"/vitrine_*.deb)
[ -f "${debs[0]}" ] || fail "no vitrine_*.deb in $work ($(ls "$work"))"
deb="${debs[0]}"
dpkg-deb -c "$deb" | awk '{print $NF}' > "$work/files.txt"
for f in ./usr/bin/vitrine ./usr/share/vitrine/shaders/common/brdf.glsl ./usr/share/vitrine/data/ocio/config.ocio \
         ./usr/share/vitrine/data/luts/warm_film.cube ./usr/share/vitrine/graphs/museum.json; do
    grep -qxF "$f" "$work/files.txt" || fail "$f is not in $deb (list: $work/files.txt)"
done
if [ -f "$src/editor/dist/index.html" ]; then
    grep -qxF ./usr/share/vitrine/editor/dist/index.html "$work/files.txt" || fail "the editor bundle is not in $deb"
fi
# The Python module (when built) in /usr/lib/python3/dist-packages, and the Python it needs in Depends.
python_module=0
if compgen -G "$build/python/vitrine*.so" > /dev/null; then
    python_module=1
    grep -qE '^\./usr/lib/python3/dist-packages/vitrine\.cpython-[0-9]+-[a-z0-9_-]+\.so$' "$work/files.txt" ||
        fail "the Python module is not in $deb under /usr/lib/python3/dist-packages (list: $work/files.txt)"
fi
depends="$(dpkg-deb -f "$deb" Depends)"
if [ "$python_module" = 1 ]; then
    [[ "$depends" == *python3-numpy* ]] || fail "Depends lacks python3-numpy (the Python module imports it): '$depends'"
fi
[[ "$depends" == *libvulkan1* ]] || fail "Depends lacks libvulkan1: '$depends'"
[[ "$depends" == *libc6* ]] || fail "Depends lacks libc6: '$depends'"
echo "install.deb: $deb, $(stat -c %s "$deb") bytes, $(wc -l < "$work/files.txt") entries"
echo "Depends: $depends"
