#!/usr/bin/env bash
# Mutation check: applies each mutation of tests/mutants.txt to a scratch copy, runs the tests named for it, and
# reports every mutation that no test caught (a "survivor"). Exit status 1 when any survives, 2 on a broken entry
# (a sed edit that changes nothing, a file that does not exist).
#
#   bash tools/mutants.sh [--list FILE] [--build DIR] [--check-list] [FILTER]
#
# --check-list runs no test: it only checks that every entry still applies (each file exists, each sed edit changes
# it, the line has the FILE ;; SED ;; CTEST-REGEX ;; DESCRIPTION shape and, when --build has a configured tree, the
# regex selects some test). Seconds for the whole list; CI runs it as the ctest `mutants.list`, so an entry whose code
# moved fails before the list can rot.
#
# FILTER (a grep -E pattern) keeps the entries whose line matches it, e.g. `deferred` or `flip`.
#
# Shader mutations (files under shaders/) run against the already-built tree: the mutated copy of shaders/ is
# given to every test through VITRINE_SHADER_DIR, and the tests' SPIR-V cache (build/test-cache) is emptied
# before and after each run (it is keyed by the preprocessed source, so nothing stale could be served anyway).
# C++ mutations are built in a scratch copy of the source tree (.mutants/ beside build/, with its own build
# directory, reused between runs) and run there. Needs `bash tools/build.sh` first.
set -uo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

list=tests/mutants.txt
build=build
filter=""
check_only=0
while [ $# -gt 0 ]; do
    case "$1" in
        --list) list=$2; shift 2 ;;
        --build) build=$2; shift 2 ;;
        --check-list) check_only=1; shift ;;
        -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
        *) filter=$1; shift ;;
    esac
done
trim() { local s=$1; s=${s#"${s%%[![:space:]]*}"}; s=${s%"${s##*[![:space:]]}"}; printf '%s' "$s"; }
[ -f "$list" ] || { echo "mutants: no list $list" >&2; exit 2; }

# --check-list: every entry must still change its files (and name tests that exist); nothing is built or run.
if [ $check_only -eq 1 ]; then
    tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
    all_tests=""
    [ -f "$build/CTestTestfile.cmake" ] && all_tests=$(ctest --test-dir "$build" -N 2>/dev/null | sed -n 's/^ *Test *#[0-9]*: //p')
    total=0; stale=0; lineno=0
    while IFS= read -r line || [ -n "$line" ]; do
        lineno=$((lineno + 1))
        [[ -z "$(trim "$line")" || "$(trim "$line")" == \#* ]] && continue
        [ -n "$filter" ] && ! grep -qE -- "$filter" <<<"$line" && continue
        total=$((total + 1))
        IFS=$'\x1f' read -r -a fields <<<"${line// ;; /$'\x1f'}"
        n=${#fields[@]}
        where="$list:$lineno"
        if [ "$n" -lt 4 ] || [ $((n % 2)) -ne 0 ]; then
            echo "STALE   $where: expected FILE ;; SED [;; FILE ;; SED ...] ;; CTEST-REGEX ;; DESCRIPTION"
            stale=$((stale + 1)); continue
        fi
        what=$(trim "${fields[n - 1]}"); tests=$(trim "${fields[n - 2]}")
        for ((i = 0; i < n - 2; i += 2)); do
            f=$(trim "${fields[i]}"); e=$(trim "${fields[i + 1]}")
            if [ ! -f "$f" ]; then echo "STALE   $where: $f: no such file ($what)"; stale=$((stale + 1)); continue 2; fi
            cp "$f" "$tmp/copy"
            if ! sed -i -e "$e" "$tmp/copy" 2>"$tmp/err"; then
                echo "STALE   $where: $f: the edit '$e' is not a valid sed script: $(head -1 "$tmp/err") ($what)"
                stale=$((stale + 1)); continue 2
            fi
            if cmp -s "$f" "$tmp/copy"; then
                echo "STALE   $where: $f: the edit '$e' changes nothing ($what)"; stale=$((stale + 1)); continue 2
            fi
        done
        if [ -n "$all_tests" ] && ! grep -qE -- "$tests" <<<"$all_tests"; then
            echo "STALE   $where: /$tests/ selects no test ($what)"; stale=$((stale + 1)); continue
        fi
    done < "$list"
    echo "mutants: $total entr$([ $total -eq 1 ] && echo y || echo ies) checked, $stale stale$([ -z "$all_tests" ] && echo " (test names not checked: no build in $build)")"
    [ $stale -gt 0 ] && exit 1
    exit 0
fi

[ -f "$build/CTestTestfile.cmake" ] || { echo "mutants: no build in $build; run bash tools/build.sh first" >&2; exit 2; }

scratch=$root/.mutants
mkdir -p "$scratch"
log=$scratch/log
: > "$log"


# A scratch source tree for C++ mutations: the tracked files of the working tree, refreshed before each run.
cxx_tree_ready=0
prepare_cxx_tree() {
    [ $cxx_tree_ready -eq 1 ] && return 0
    echo "mutants: preparing the C++ scratch tree in $scratch/src (first build there takes a while)"
    mkdir -p "$scratch/src"
    # Only files whose content differs are copied, so the scratch build stays incremental between runs.
    while IFS= read -r -d '' f; do
        cmp -s "$f" "$scratch/src/$f" || { mkdir -p "$scratch/src/$(dirname "$f")"; cp "$f" "$scratch/src/$f"; }
    done < <(git ls-files -z --cached --others --exclude-standard)
    launcher=()
    command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
    cmake -S "$scratch/src" -B "$scratch/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >>"$log" 2>&1 &&
        cmake --build "$scratch/build" -j "$(nproc)" >>"$log" 2>&1 ||
        { echo "mutants: the scratch tree does not build; see $log" >&2; exit 2; }
    cxx_tree_ready=1
}

total=0; caught=0; survivors=(); broken=0
while IFS= read -r line || [ -n "$line" ]; do
    [[ -z "$(trim "$line")" || "$(trim "$line")" == \#* ]] && continue
    [ -n "$filter" ] && ! grep -qE -- "$filter" <<<"$line" && continue
    # FILE ;; SED [;; FILE ;; SED ...] ;; CTEST-REGEX ;; DESCRIPTION — one mutation may edit several files.
    IFS=$'\x1f' read -r -a fields <<<"${line// ;; /$'\x1f'}"
    n=${#fields[@]}
    total=$((total + 1))
    if [ "$n" -lt 4 ] || [ $((n % 2)) -ne 0 ]; then
        echo "BROKEN  line '$line': expected FILE ;; SED [;; FILE ;; SED ...] ;; CTEST-REGEX ;; DESCRIPTION"
        broken=$((broken + 1)); continue
    fi
    tests=$(trim "${fields[n - 2]}"); what=$(trim "${fields[n - 1]}")
    files=(); edits=(); cxx=0
    for ((i = 0; i < n - 2; i += 2)); do
        files+=("$(trim "${fields[i]}")"); edits+=("$(trim "${fields[i + 1]}")")
        [[ "${files[-1]}" != shaders/* ]] && cxx=1
    done
    first=${files[0]}

    # Shader-only mutations run on the main build with a mutated copy of shaders/; anything touching C++ runs in
    # the scratch tree (shaders included, which that build reads from its own source tree).
    if [ $cxx -eq 0 ]; then
        rm -rf "$scratch/shaders-run"; mkdir -p "$scratch/shaders-run"; cp -r shaders "$scratch/shaders-run/shaders"
        base=$scratch/shaders-run
        runner=(env "VITRINE_SHADER_DIR=$scratch/shaders-run/shaders" ctest --test-dir "$build")
        cache=$build/test-cache
    else
        prepare_cxx_tree
        base=$scratch/src
        runner=(ctest --test-dir "$scratch/build")
        cache=$scratch/build/test-cache
    fi
    ok=1
    for ((i = 0; i < ${#files[@]}; ++i)); do
        f=${files[i]}
        if [ ! -f "$f" ]; then echo "BROKEN  $f: no such file ($what)"; ok=0; break; fi
        cmp -s "$f" "$base/$f" || cp "$f" "$base/$f"
        cp "$base/$f" "$scratch/original.$i"
        sed -i -e "${edits[i]}" "$base/$f"
        if cmp -s "$base/$f" "$scratch/original.$i"; then
            echo "BROKEN  $f: the edit '${edits[i]}' changes nothing ($what)"; ok=0; break
        fi
    done
    restore() {
        if [ $cxx -eq 1 ]; then
            for ((j = 0; j < ${#files[@]}; ++j)); do
                [ -f "$scratch/original.$j" ] && cp "$scratch/original.$j" "$base/${files[j]}"
            done
        fi
        rm -f "$scratch"/original.*
    }
    if [ $ok -eq 0 ]; then broken=$((broken + 1)); restore; continue; fi

    if [ $cxx -eq 1 ] && ! cmake --build "$scratch/build" -j "$(nproc)" >>"$log" 2>&1; then
        echo "BROKEN  $first: the mutated tree does not compile ($what)"
        broken=$((broken + 1)); restore; continue
    fi
    status=0
    if true; then
        rm -rf "$cache"
        {
            echo "=== ${files[*]} :: ${edits[*]} :: $tests"
            "${runner[@]}" -R "$tests" --output-on-failure --no-tests=error -j "$(nproc)" --timeout 600 2>&1
        } >>"$log" 2>&1
        status=$?
        rm -rf "$cache"
    fi
    restore

    # A regex that selects no test is a broken entry, not a catch (ctest fails with --no-tests=error).
    if tac "$log" | sed -n '1,/^=== /p' | grep -q "No tests were found"; then
        echo "BROKEN  $first: /$tests/ selects no test ($what)"
        broken=$((broken + 1)); continue
    fi
    if [ $status -ne 0 ]; then
        caught=$((caught + 1))
        failed=$(tac "$log" | sed -n '1,/^=== /p' | grep -oE '^\s*[0-9]+ - [^ ]+' | awk '{print $3}' | sort -u |
                 head -4 | paste -sd ' ' -)
        echo "caught  $first: $what — ${failed:-tests failed}"
    else
        survivors+=("$first: $what")
        echo "SURVIVE $first: $what — no test matching /$tests/ failed"
    fi
done < "$list"

if [ $cxx_tree_ready -eq 1 ]; then cmake --build "$scratch/build" -j "$(nproc)" >>"$log" 2>&1; fi
echo
echo "mutants: $total mutation(s), $caught caught, ${#survivors[@]} survived, $broken broken (log: $log)"
for s in "${survivors[@]}"; do echo "  survived: $s"; done
[ $broken -gt 0 ] && exit 2
[ ${#survivors[@]} -gt 0 ] && exit 1
exit 0
