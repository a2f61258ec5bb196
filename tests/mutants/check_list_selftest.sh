#!/usr/bin/env bash
# The checker behind `mutants.list` (tools/mutants.sh --check-list) must itself fail on a stale list: a synthetic
# list with one live entry and one whose sed edit no longer changes its file (as happens when code moves) must be
# rejected naming the stale line and only it; so must a missing file, a malformed line and an invalid sed script;
# the live entry alone must pass.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail=0
build=/nonexistent
expect() { # NAME WANT-STATUS WANT-GREP LIST-CONTENT
    printf '%s\n' "$4" > "$tmp/list"
    out=$(bash "$root/tools/mutants.sh" --check-list --list "$tmp/list" --build /nonexistent 2>&1); st=$?
    if [ "$st" -ne "$2" ] || ! grep -qE -- "$3" <<<"$out"; then
        echo "FAIL $1: status $st (want $2), output:"; echo "$out" | sed 's/^/    /'; fail=1
    else
        echo "ok   $1"
    fi
}
live='shaders/common/brdf.glsl ;; s|float lambertDiffuse() { return 1.0 / kPi; }|float lambertDiffuse() { return 1.0; }| ;; gpu.Shading ;; Lambert without 1/pi'
stale='shaders/common/brdf.glsl ;; s/this text is not in the file/x/ ;; gpu.Shading ;; a mutation whose code moved'
expect "live entry passes"            0 '1 entry checked, 0 stale' "$live"
expect "stale entry fails"            1 "list:3: shaders/common/brdf.glsl: the edit .* changes nothing \(a mutation whose code moved\)" \
       "# comment
$live
$stale"
expect "only the stale line is named" 1 '2 entries checked, 1 stale' "$live
$stale"
expect "missing file fails"           1 'no/such/file.glsl: no such file' 'no/such/file.glsl ;; s/a/b/ ;; gpu ;; gone'
expect "malformed line fails"         1 'expected FILE ;; SED' 'shaders/common/brdf.glsl ;; s/a/b/'
expect "invalid sed fails"            1 'not a valid sed script' 'shaders/common/brdf.glsl ;; s/(/ ;; gpu ;; bad sed'
# With a configured build tree (first argument), a regex that selects no test is stale too.
if [ -n "${1:-}" ] && [ -f "$1/CTestTestfile.cmake" ]; then
    printf '%s\n' "${live/gpu.Shading/no.such.test.name}" > "$tmp/list"
    out=$(bash "$root/tools/mutants.sh" --check-list --list "$tmp/list" --build "$1" 2>&1); st=$?
    if [ "$st" -eq 1 ] && grep -q "selects no test" <<<"$out"; then echo "ok   regex selecting no test fails"
    else echo "FAIL regex selecting no test: status $st: $out"; fail=1; fi
fi
[ $fail -eq 0 ] && echo "check_list_selftest: all cases behave" || exit 1
