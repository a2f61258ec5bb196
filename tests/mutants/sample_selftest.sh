#!/usr/bin/env bash
# tools/mutants_sample.py draws edits that apply: every line it writes for two seeds passes tools/mutants.sh
# --check-list (the edit changes its file, the regex selects a test), each seed gives at least 60 of them, the two
# seeds differ, the path tracers' shaders come only with --tracers, and a --match that no shader has is an error.
set -euo pipefail
build=$1
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$root"
for seed in 3 4; do
    /usr/bin/python3 tools/mutants_sample.py --seed "$seed" --per-file 2 > "$tmp/sample$seed.txt"
    n=$(grep -c ' ;; audit: ' "$tmp/sample$seed.txt")
    [ "$n" -ge 60 ] || { echo "sample_selftest: seed $seed drew $n edits, expected at least 60" >&2; exit 1; }
    bash tools/mutants.sh --check-list --build "$build" --list "$tmp/sample$seed.txt"
done
if cmp -s "$tmp/sample3.txt" "$tmp/sample4.txt"; then echo "sample_selftest: two seeds drew the same edits" >&2; exit 1; fi
# The path tracers' shaders are drawn with --tracers only, and then alone.
tracers='^shaders/(pathtrace/|render/|reference/|bake/lightmap)'
if grep -qE "$tracers" "$tmp/sample3.txt"; then echo "sample_selftest: a path tracer drawn without --tracers" >&2; exit 1; fi
/usr/bin/python3 tools/mutants_sample.py --seed 3 --per-file 1 --tracers > "$tmp/tracers.txt"
n=$(grep -cE "$tracers" "$tmp/tracers.txt")
[ "$n" -ge 6 ] && [ "$n" -eq "$(grep -c ' ;; audit: ' "$tmp/tracers.txt")" ] ||
    { echo "sample_selftest: --tracers drew $n path tracer edits among others, or fewer than 6" >&2; exit 1; }
bash tools/mutants.sh --check-list --build "$build" --list "$tmp/tracers.txt"
if /usr/bin/python3 tools/mutants_sample.py --match no/such/shader > /dev/null 2>&1; then
    echo "sample_selftest: a --match that selects nothing did not fail" >&2
    exit 1
fi
echo "sample_selftest: ok"
