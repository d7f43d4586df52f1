#!/bin/sh
# Short, bounded libFuzzer runs of the binary protocol's decoders
# (tests/fuzz/fuzz_binary.c), of the EXR readers, flat and deep, with
# their object masks (tests/fuzz/fuzz_exr.c), and of the other files a user or a farm hands
# obscura (tests/fuzz/fuzz_files.c: camera JSON, mask selectors, a .glb's
# LODs, the dynamic model, bake and bake-dynamic parts, regions and
# decorators files; its seeds replay the inputs that crashed it), on their
# seeds, and the mesh and level loaders' seeds (tests/fuzz/fuzz_scene.c,
# replayed only, see below): fails on a crash, a read past the buffer, undefined behaviour, a
# leak or an allocation past the limit.  Needs clang (libFuzzer);
# without it, prints "skip".  The fuzzer carries its own sanitizers, so it
# runs once, in the plain build (BUILD without "asan").
#
#   BUILD=build tests/e2e/fuzz.sh      (FUZZ_SECONDS, default 20)
#
# FUZZ_SECONDS=0: every target replays its seeds and regression inputs
# only (libFuzzer -runs=0), no mutation: the same inputs on every run, as
# `make test-long` runs it (it installs clang first).
set -u
BUILD=${BUILD:-build}
SECONDS_MAX=${FUZZ_SECONDS:-20}
case $BUILD in
*asan*) echo "  skip fuzz: runs in the plain build only"; exit 0 ;;
esac
if ! command -v "${FUZZ_CC:-clang}" >/dev/null 2>&1; then
    echo "  skip fuzz: clang not found (libFuzzer)"
    exit 0
fi
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
if ! make --no-print-directory -s fuzz BUILD="$BUILD" >"$T/build" 2>&1; then
    echo "  FAIL fuzz: make fuzz failed"
    sed 's/^/       /' "$T/build" | tail -10
    exit 1
fi
# fuzz TARGET WHAT SEED_DIR...: a bounded run; new inputs go to a scratch
# corpus, the committed seeds are only read.
rc=0
fuzz() {
    target=$1 what=$2
    shift 2
    rm -rf "$T/corpus" && mkdir -p "$T/corpus"
    if [ "$SECONDS_MAX" = 0 ]; then
        if "$BUILD/fuzz/$target" -runs=0 -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$T/" \
                "$@" >"$T/log" 2>&1; then
            echo "  ok   fuzz: $what, $(find "$@" -type f | wc -l) seeds replayed, no crash"
            return
        fi
    elif "$BUILD/fuzz/$target" -max_total_time="$SECONDS_MAX" -runs=2000000 -timeout=10 \
            -rss_limit_mb=2048 -max_len=2000000 -artifact_prefix="$T/" -print_final_stats=1 \
            "$T/corpus" "$@" >"$T/log" 2>&1; then
        runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$T/log")
        cov=$(grep -o 'cov: [0-9]*' "$T/log" | tail -1)
        echo "  ok   fuzz: $what, ${runs:-?} inputs, $cov, no crash"
        return
    fi
    rc=1
    echo "  FAIL fuzz: $what crashed (libFuzzer log, tail):"
    tail -40 "$T/log" | sed 's/^/       /'
    for a in "$T"/crash-* "$T"/leak-* "$T"/timeout-* "$T"/oom-*; do
        [ -e "$a" ] || continue
        mkdir -p "$BUILD/fuzz/artifacts" && cp "$a" "$BUILD/fuzz/artifacts/"
        echo "       input kept: $BUILD/fuzz/artifacts/$(basename "$a")"
    done
}
fuzz fuzz_binary "binary protocol decoders" tests/fuzz/corpus/binary
mkdir -p "$T/exr_seeds" && cp tests/data/*.exr tests/data/small/*.exr tests/data/crypto_sidecar/*.exr \
    "$T/exr_seeds/"
fuzz fuzz_exr "EXR readers (flat and deep) and their object masks" tests/data/damaged "$T/exr_seeds"
fuzz fuzz_files "file parsers (camera, masks, LODs, dynamic model, parts, regions, decorators)" \
    tests/fuzz/corpus/files
# The mesh and level loaders (tests/fuzz/fuzz_scene.c: assimp, then
# obscura's checks and the bake's flattening): the committed seeds and
# regression inputs replayed, not mutated, as assimp 5.2's own importers
# (not obscura's code) crash on some mutated inputs within a minute (see
# tests/fuzz/fuzz.mk); a long run is by hand.  assimp's own leaks are
# suppressed (tests/fuzz/scene.supp; it needs the slow unwinder).
if ASAN_OPTIONS=fast_unwind_on_malloc=0 LSAN_OPTIONS=suppressions="$PWD/tests/fuzz/scene.supp" \
        "$BUILD/fuzz/fuzz_scene" -runs=0 -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$T/" \
        tests/fuzz/corpus/scene >"$T/log" 2>&1; then
    echo "  ok   fuzz: mesh and level loaders, $(ls tests/fuzz/corpus/scene | wc -l) seeds replayed, no crash"
else
    rc=1
    echo "  FAIL fuzz: mesh and level loaders crashed on a seed (libFuzzer log, tail):"
    tail -40 "$T/log" | sed 's/^/       /'
fi
exit $rc
