#!/usr/bin/env bash
# Fuzzes the graph loader and the glTF/GLB loader with libFuzzer (clang, AddressSanitizer, UndefinedBehaviorSanitizer).
#
#   bash tools/fuzz.sh [SECONDS] [graph|gltf]...     (default: 60 seconds each, both targets)
#
# Builds build-fuzz/ (its own build directory, clang, -DVITRINE_FUZZ=ON) and runs each fuzzer for SECONDS, starting
# from the seed corpus tests/fuzz/corpus/<target>/ and the regressions tests/fuzz/regressions/<target>/; inputs it
# finds interesting accumulate in build-fuzz/fuzz/corpus/<target>/ across runs. A crash, hang, leak or sanitizer
# report stops that fuzzer and leaves the input in build-fuzz/fuzz/artifacts/<target>/: fix the bug, then copy the
# input into tests/fuzz/regressions/<target>/ so that every build's ctest replays it (fuzz.Regressions.*).
# Prints executions per second and totals per target; exits 1 when any fuzzer found something.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(graph gltf)
for t in "${targets[@]}"; do
    [ "$t" = graph ] || [ "$t" = gltf ] || { echo "fuzz.sh: unknown target '$t'; expected graph or gltf" >&2; exit 2; }
done

bash tools/install-deps.sh --fuzz
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
    -DCMAKE_CXX_COMPILER=clang++ -DVITRINE_FUZZ=ON -DVITRINE_BUILD_BENCHMARKS=OFF "${launcher[@]}" >/dev/null
cmake --build build-fuzz -j"${JOBS:-$(nproc)}" --target "${targets[@]/#/fuzz_}"

found=0
for t in "${targets[@]}"; do
    corpus=build-fuzz/fuzz/corpus/$t
    artifacts=build-fuzz/fuzz/artifacts/$t
    log=build-fuzz/fuzz/$t.log
    mkdir -p "$corpus" "$artifacts"
    echo "fuzz.sh: fuzz_$t for ${seconds}s (log: $log)"
    status=0
    # -rss_limit_mb: the loaders must refuse absurd sizes before allocating, so 2 GB of memory is a finding.
    "build-fuzz/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -print_final_stats=1 -rss_limit_mb=2048 \
        -timeout=20 -dict="tests/fuzz/$t.dict" -artifact_prefix="$artifacts/" \
        "$corpus" "tests/fuzz/corpus/$t" "tests/fuzz/regressions/$t" >"$log" 2>&1 || status=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    echo "fuzz.sh: fuzz_$t: ${runs:-?} executions, ${rate:-?} exec/s, exit status $status"
    if [ "$status" -ne 0 ]; then
        found=1
        grep -E "^==[0-9]+==ERROR|runtime error|SUMMARY|Test unit written" "$log" | head -5 || true
    fi
done
exit $found
