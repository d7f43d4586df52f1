#!/bin/sh
# The GPU path (issue 22, part 3) in one bounded run, for a machine with
# an NVIDIA (or any hardware EGL) device: builds, checks that the EGL
# device backend exists, runs VAO++ Table 1 at 1920x1080 and 3840x2160 and
# Table 2 at 1080p on it (bench/extensions_bench.c), the cold start
# (bench/coldstart.sh: here obscura's program binaries are the only
# cache), then the test suite with OBSCURA_BACKEND=egl-device: `make
# check` (the first half of `make test`), then the ASan/UBSan half with
# the time that is left.  Benchmarks first: they are short and are what
# the device is lent for; every step has a time limit, so the whole run
# ends within GPU_SH_BUDGET seconds (default 540) plus the build.
#
#   OUT=DIR bench/gpu.sh            results in DIR (default ./gpu-results)
#   bench/gpu.sh --check            the same steps on this machine's own
#                                   backend (OBSCURA_BACKEND unset, auto),
#                                   at 320x240, with one unit and one e2e
#                                   test instead of the suite: shows that
#                                   the script works without a GPU
#
#   GPU_SH_PREBUILT=DIR bench/gpu.sh
#                                   no build: the binaries, libraries and
#                                   data that bench/gpu_pack.sh put in DIR
#                                   (1 means .gpu), for a machine without
#                                   the build dependencies; the test step
#                                   is then the packed unit-test binaries,
#                                   each alone (the e2e scripts and the
#                                   ASan half need make, a compiler, curl,
#                                   python3, node and oiiotool)
#
# Writes to OUT: summary.txt (one line per step: exit status, seconds),
# info.txt, nvidia-smi.txt (when there is one), table1-1080p.md,
# table1-4k.md, table2-1080p.md, coldstart.md, test.log, test-asan.log,
# failures.txt, and each step's log.  Exit status: 2 when there is no EGL
# device (nothing else is run), 1 when a step failed or ran out of time,
# 0 otherwise.
set -u
OUT=${OUT:-./gpu-results}
BUDGET=${GPU_SH_BUDGET:-540}
JOBS=$(nproc 2>/dev/null || echo 2)
CHECK=0
# --units LIMIT BINARY...: (the prebuilt test step) each binary alone, at
# most LIMIT seconds each, from the repository root with a private temp dir
# as tests/run_unit.sh runs them
if [ "${1:-}" = --units ]; then
    lim=$2
    shift 2
    OBSCURA_TEST_TMP=$(mktemp -d)
    export OBSCURA_TEST_TMP
    n=0 bad=0
    for t in "$@"; do
        n=$((n + 1))
        timeout -k 5 "$lim" "$t" || { echo "FAILED: $t (exit $?)"; bad=$((bad + 1)); }
    done
    rm -rf "$OBSCURA_TEST_TMP"
    echo "unit binaries: $((n - bad)) of $n passed"
    [ $bad -eq 0 ]
    exit
fi
case "${1:-}" in
--check) CHECK=1 ;;
"") ;;
*) echo "usage: bench/gpu.sh [--check]  (OUT=DIR for the results)" >&2; exit 2 ;;
esac
mkdir -p "$OUT" || exit 1
: > "$OUT/summary.txt"
failed=0
t_start=$(date +%s)

say() { echo "gpu.sh: $*" | tee -a "$OUT/summary.txt"; }
left() { echo $((BUDGET - ($(date +%s) - t_start))); }
# step NAME LIMIT CMD...: runs CMD with output in OUT/NAME.log, at most
# LIMIT seconds (and never past the budget); records its exit status
step() {
    name=$1 limit=$2
    shift 2
    l=$(left)
    [ "$limit" -gt "$l" ] && limit=$l
    if [ "$limit" -lt 10 ]; then
        say "$name: skipped, the time budget ($BUDGET s) is spent"
        failed=1
        return 1
    fi
    t0=$(date +%s)
    timeout -k 10 "$limit" "$@" > "$OUT/$name.log" 2>&1
    rc=$?
    dt=$(($(date +%s) - t0))
    case $rc in
    0) say "$name: ok in $dt s" ;;
    124 | 137) say "$name: stopped at its time limit ($limit s)"; failed=1 ;;
    *) say "$name: exit $rc in $dt s (see $name.log)"; failed=1 ;;
    esac
    return $rc
}

if [ $CHECK -eq 1 ]; then
    unset OBSCURA_BACKEND
    BACKEND=auto
    SIZES_1080=320x240 SIZES_4K="" FRAMES=3
    say "check run: backend auto (OBSCURA_BACKEND unset), 320x240, no test suite"
else
    export OBSCURA_BACKEND=egl-device
    BACKEND=egl-device
    SIZES_1080=1920x1080 SIZES_4K=3840x2160 FRAMES=15
fi
PRE=${GPU_SH_PREBUILT:-}
[ "$PRE" = 1 ] && PRE=.gpu
if [ -n "$PRE" ]; then
    BUILD=$PRE/build
    export LD_LIBRARY_PATH="$PRE/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    export OBSCURA_SHARED_DATA="${OBSCURA_SHARED_DATA:-$PRE/data}"
else
    BUILD=build
fi
say "$(date -u '+%Y-%m-%d %H:%M UTC'), $(uname -m), $JOBS cores, budget $BUDGET s"

# ---- build (outside the budget: make is quick on many cores) -------------
BIN="all build/extensions_bench build/exr_upscale"
if [ -n "$PRE" ]; then
    say "build: none, prebuilt binaries from $PRE ($PRE/lib on LD_LIBRARY_PATH)"
elif ! timeout -k 10 600 make -j"$JOBS" $BIN > "$OUT/build.log" 2>&1; then
    say "build failed (see build.log)"
    tail -20 "$OUT/build.log"
    exit 1
else
    say "build: ok"
fi
t_start=$(date +%s)

# ---- the device -----------------------------------------------------------
command -v nvidia-smi > /dev/null 2>&1 && nvidia-smi > "$OUT/nvidia-smi.txt" 2>&1
if ! "$BUILD/obscura" info --backend "$BACKEND" > "$OUT/info.txt" 2>&1; then
    say "no EGL device: 'obscura info --backend $BACKEND' failed:"
    sed 's/^/    /' "$OUT/info.txt" | tee -a "$OUT/summary.txt"
    say "(on NVIDIA the driver's EGL library and its glvnd vendor file must be" \
        "present: /usr/share/glvnd/egl_vendor.d/10_nvidia.json)"
    exit 2
fi
say "device: $(sed -n 's/^GL renderer: //p' "$OUT/info.txt"), $(sed -n 's/^GL version: //p' "$OUT/info.txt")"

# ---- VAO++ Table 1 and 2 ---------------------------------------------------
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
OBJ=$SHARED/blender/room.obj
CAM=$SHARED/blender/room.camera.json
G=$OUT/gbuffers
mkdir -p "$G"
# room.obj rasterised at each size (the G-buffers of the paper's tables),
# else the bundled room_small scaled by extensions_bench (nearest)
gbuffer() { # SIZE: prints the G-buffer arguments for extensions_bench
    if [ -f "$OBJ" ] && "$BUILD/obscura" gbuffer "$OBJ" --camera "$CAM" --backend "$BACKEND" \
        --width "${1%x*}" --height "${1#*x}" -o "$G/$1.exr" -q > "$G/$1.log" 2>&1; then
        echo "$G/$1.exr"
    else
        echo "tests/data/room_small.exr tests/data/room_small.camera.json"
    fi
}
# shellcheck disable=SC2046
step table1-1080p 150 "$BUILD/extensions_bench" --backend "$BACKEND" --frames "$FRAMES" \
    --sizes "$SIZES_1080" $(gbuffer "$SIZES_1080")
cp "$OUT/table1-1080p.log" "$OUT/table1-1080p.md"
if [ -n "$SIZES_4K" ]; then
    # shellcheck disable=SC2046
    step table1-4k 150 "$BUILD/extensions_bench" --backend "$BACKEND" --frames 9 --frames-4k 9 \
        --sizes "$SIZES_4K" $(gbuffer "$SIZES_4K")
    cp "$OUT/table1-4k.log" "$OUT/table1-4k.md"
fi
# shellcheck disable=SC2046
step table2-1080p 90 "$BUILD/extensions_bench" --methods --backend "$BACKEND" --frames "$FRAMES" \
    --sizes "$SIZES_1080" $(gbuffer "$SIZES_1080")
cp "$OUT/table2-1080p.log" "$OUT/table2-1080p.md"

# ---- cold start: a process with obscura's program cache warm --------------
# NVIDIA's own shader cache (~/.nv/GLCache) off: obscura's program binaries are
# then the only cache, as on a fresh container, and "cold" is cold
step coldstart 90 env BUILD="$BUILD" RUNS=5 __GL_SHADER_DISK_CACHE=0 sh "$(dirname "$0")/coldstart.sh"
cp "$OUT/coldstart.log" "$OUT/coldstart.md"

# ---- the tests --------------------------------------------------------------
if [ -n "$PRE" ]; then
    if [ $CHECK -eq 1 ]; then
        UNITS=$BUILD/tests/core/test_progcache
    else
        UNITS=$(ls "$BUILD"/tests/*/test_* 2> /dev/null)
    fi
    say "tests: the packed unit binaries only; not run: the e2e scripts, make check's" \
        "headers/loops/readme-check and the ASan half (no make, compiler, curl, node or" \
        "oiiotool on this machine, and no ASan build was packed)"
    if [ -z "$UNITS" ]; then
        say "test: skipped, no unit binaries in $BUILD/tests"
    else
        # shellcheck disable=SC2086
        step test 330 sh "$0" --units 60 $UNITS
    fi
elif [ $CHECK -eq 1 ]; then
    make -j"$JOBS" build/tests/core/test_progcache build/obscurad > "$OUT/test-build.log" 2>&1
    step test 120 sh -c 'OBSCURA_TEST_TMP=$(mktemp -d) build/tests/core/test_progcache &&
        OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/progcache.sh'
else
    # the binaries in parallel, the tests themselves one after another
    UNITS=$(ls tests/unit/*/test_*.c | sed 's|^tests/unit/\(.*\)\.c$|build/tests/\1|')
    # shellcheck disable=SC2086
    make -j"$JOBS" $UNITS build/obscurad > "$OUT/test-build.log" 2>&1
    step test 330 make check
    # the sanitizer half of make test with what is left
    # shellcheck disable=SC2086
    make -j"$JOBS" BUILD=build/asan SAN=1 all \
        $(echo "$UNITS" | sed 's|build/tests/|build/asan/tests/|g') > "$OUT/test-asan-build.log" 2>&1
    step test-asan 330 make check BUILD=build/asan SAN=1
fi
grep -hE '^  FAIL |FAILED|^\[  FAILED  \]|Sanitizer' "$OUT"/test*.log 2>/dev/null | sort | uniq -c > "$OUT/failures.txt"
if [ -n "$PRE" ]; then
    say "tests: $(grep -h '^unit binaries:' "$OUT"/test.log 2>/dev/null || echo 'no unit summary') (failures.txt)"
else
    say "tests: $(grep -h '^  ok ' "$OUT"/test.log 2>/dev/null | wc -l) e2e checks passed," \
        "$(grep -hc '^  FAIL ' "$OUT"/test*.log 2>/dev/null | awk '{s += $1} END {print s + 0}') failed" \
        "(failures.txt)"
fi
say "done in $(($(date +%s) - t_start)) s; results in $OUT"
exit $failed
