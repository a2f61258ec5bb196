#!/usr/bin/env bash
# ctest install.prefix: `cmake --install` into a temporary prefix, then the installed vitrine renders
# graphs/fxaa_zoneplate.json and graphs/museum.json at 160x90 with the source tree out of reach: inside a private
# mount namespace (unshare, no root needed) the source tree's shaders/, data/ and graphs/ are covered by empty
# folders, and VITRINE_NO_SOURCE_TREE=1 turns off the compiled-in source-tree fallback as well. Controls that make the
# test able to fail: the build tree's binary must fail under the same conditions (so the covering works), and the
# installed copy's images must equal, byte for byte, the build tree's renders of the same graphs (so it read the same
# shaders and data, not something else).
# Usage: install_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src="$(cd "$1" && pwd)"
build="$(cd "$2" && pwd)"
work="$build/install-test"
rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
# The GPU tests' cache folder (kept between runs): the Museum's bake and probes are made once (minutes on lavapipe) and
# loaded by both renders here; the installed copy's shaders have the same content, so the same cache keys.
export VITRINE_CACHE_DIR="${VITRINE_CACHE_DIR:-$build/test-cache}"

fail() { echo "install.prefix: FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
for f in bin/vitrine share/vitrine/shaders/common/brdf.glsl share/vitrine/data/ocio/config.ocio \
         share/vitrine/data/luts/warm_film.cube share/vitrine/data/models/showcase.gltf \
         share/vitrine/graphs/museum.json share/vitrine/graphs/fxaa_zoneplate.json; do
    [ -f "$prefix/$f" ] || fail "$f is not installed (install log: $work/install.log)"
done
ls "$prefix/share/vitrine/data/lenses/"*.json > /dev/null || fail "data/lenses is not installed"

version="$("$prefix/bin/vitrine" --version)"
echo "$version"
[[ "$version" =~ ^vitrine\ [0-9]+\.[0-9]+\.[0-9]+\ \(commit\ ([0-9a-f]{12}(-dirty)?|unknown)\)$ ]] ||
    fail "--version printed '$version'"

# Per graph: the zone plate with validation; the Museum without it and with a cheap bake and probe capture: what is
# checked here is that the installed copy finds its shaders and data, and under validation on lavapipe the Museum's
# probe capture alone takes many minutes from a cold cache (golden.check validates the Museum graph itself).
common=(--set frame.width=160 --set frame.height=90 --quiet --exr none --overwrite)
declare -A extra
extra[fxaa_zoneplate]="--validate"
extra[museum]="--set bake.params.samples=2 --set bake.params.max_bounces=1 --set bake.params.probe_rays=16
    --set bake.params.filter_iterations=0 --set bake.params.texels_per_meter=1 --set capture.params.size=8
    --set capture.params.samples=16 --set capture.params.lut_size=16 --set capture.params.lut_samples=256"
args=("${common[@]}" --validate)
# Reference renders from the build tree (reads the source tree).
for g in fxaa_zoneplate museum; do
    # shellcheck disable=SC2086
    "$build/vitrine" run "$src/graphs/$g.json" "${common[@]}" ${extra[$g]} --out "$work/build-tree/$g"
done

# Runs "$@" with the source tree's shaders/, data/ and graphs/ covered by empty folders and the fallback off. Where
# unprivileged mount namespaces are not allowed (some containers), only the fallback is off (said on stderr).
if unshare --map-root-user --mount true 2> /dev/null; then
    can_cover=1
else
    can_cover=0
    echo "install.prefix: unshare --map-root-user --mount is not allowed here: the source tree stays visible and only" \
         "VITRINE_NO_SOURCE_TREE=1 keeps the installed copy from using it" >&2
fi
hidden() {
    if [ "$can_cover" = 0 ]; then
        env VITRINE_NO_SOURCE_TREE=1 "$@"
        return
    fi
    unshare --map-root-user --mount bash -c '
        set -e
        src="$1"; shift
        for d in shaders data graphs; do mount -t tmpfs vitrine-hidden "$src/$d"; done
        [ -z "$(ls -A "$src/shaders")" ] || { echo "covering $src/shaders failed" >&2; exit 99; }
        exec env VITRINE_NO_SOURCE_TREE=1 "$@"' hidden "$src" "$@"
}

# Control: the build tree's binary cannot render under these conditions.
set +e
hidden "$build/vitrine" run "$prefix/share/vitrine/graphs/fxaa_zoneplate.json" "${args[@]}" --out "$work/control" \
    2> "$work/control.err"
rc=$?
set -e
[ "$rc" -eq 1 ] || fail "the build tree's binary exited $rc with the source tree hidden (expected 1); $(cat "$work/control.err")"
grep -q "VITRINE_NO_SOURCE_TREE" "$work/control.err" || fail "the control failed for another reason: $(cat "$work/control.err")"

for g in fxaa_zoneplate museum; do
    # shellcheck disable=SC2086
    hidden "$prefix/bin/vitrine" run "$prefix/share/vitrine/graphs/$g.json" "${common[@]}" ${extra[$g]} \
        --out "$work/installed/$g" ||
        fail "the installed vitrine could not render $g with the source tree hidden"
    [ -s "$work/installed/$g/final.png" ] || fail "no $work/installed/$g/final.png"
    cmp "$work/build-tree/$g/final.png" "$work/installed/$g/final.png" ||
        fail "$g: the installed copy's final.png differs from the build tree's"
done
# The Python module (when built): installed into the prefix's Debian Python folder, it finds PREFIX/share/vitrine from
# its own location; with the source tree hidden it renders the zone plate to the build tree's final.png, byte for
# byte, while the build tree's module cannot render at all (the control).
python_checked=""
if compgen -G "$build/python/vitrine*.so" > /dev/null; then
    site="$prefix/lib/python3/dist-packages"
    compgen -G "$site/vitrine*.so" > /dev/null || fail "the Python module is not installed in $site"
    render_py='
import sys, numpy as np, matplotlib.image, vitrine
g = vitrine.Graph.load(sys.argv[1], set={"frame.width": 160, "frame.height": 90}, device=vitrine.Device("", validate=True))
r = g.run(frames=1)
assert r.validation_messages == 0, r.validation_messages
png = np.round(matplotlib.image.imread(sys.argv[2]) * 255.0).astype(np.uint8)
assert np.array_equal(r.display("final"), png), "the display image differs from the build tree final.png"
print(vitrine.__file__)'
    set +e
    hidden env PYTHONPATH="$build/python" /usr/bin/python3 -c "$render_py" "$prefix/share/vitrine/graphs/fxaa_zoneplate.json" \
        "$work/build-tree/fxaa_zoneplate/final.png" > "$work/control-python.out" 2>&1
    rc=$?
    set -e
    [ "$rc" -ne 0 ] || fail "the build tree's Python module rendered with the source tree hidden"
    grep -q "VITRINE_NO_SOURCE_TREE" "$work/control-python.out" ||
        fail "the Python control failed for another reason: $(cat "$work/control-python.out")"
    hidden env PYTHONPATH="$site" /usr/bin/python3 -c "$render_py" "$prefix/share/vitrine/graphs/fxaa_zoneplate.json" \
        "$work/build-tree/fxaa_zoneplate/final.png" > "$work/installed-python.out" 2>&1 ||
        fail "the installed Python module could not render fxaa_zoneplate: $(cat "$work/installed-python.out")"
    grep -q "^$site/vitrine" "$work/installed-python.out" ||
        fail "python3 imported another vitrine module: $(cat "$work/installed-python.out")"
    python_checked="; the installed Python module rendered fxaa_zoneplate equal to the build tree's"
fi
echo "install.prefix: installed into $prefix; fxaa_zoneplate and museum rendered at 160x90 from it (source tree covered: $can_cover)$python_checked"
