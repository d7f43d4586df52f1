#!/bin/sh
# A short, bounded libFuzzer run of the binary protocol's decoders
# (tests/fuzz/fuzz_binary.c) on the seed corpus: fails on a crash, a read
# past the buffer, undefined behaviour or a leak.  Needs clang (libFuzzer);
# without it, prints "skip".  The fuzzer carries its own sanitizers, so it
# runs once, in the plain build (BUILD without "asan").
#
#   BUILD=build tests/e2e/fuzz.sh      (FUZZ_SECONDS, default 20)
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
mkdir -p "$T/corpus"
# New inputs go to $T/corpus; the committed seeds are only read.
if "$BUILD/fuzz/fuzz_binary" -max_total_time="$SECONDS_MAX" -runs=2000000 -timeout=10 \
        -rss_limit_mb=2048 -artifact_prefix="$T/" -print_final_stats=1 \
        "$T/corpus" tests/fuzz/corpus/binary >"$T/log" 2>&1; then
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$T/log")
    cov=$(grep -o 'cov: [0-9]*' "$T/log" | tail -1)
    echo "  ok   fuzz: binary protocol decoders, ${runs:-?} inputs, $cov, no crash"
    exit 0
fi
echo "  FAIL fuzz: the binary protocol's decoder crashed (libFuzzer log, tail):"
tail -40 "$T/log" | sed 's/^/       /'
for a in "$T"/crash-* "$T"/leak-* "$T"/timeout-* "$T"/oom-*; do
    [ -e "$a" ] || continue
    mkdir -p "$BUILD/fuzz/artifacts" && cp "$a" "$BUILD/fuzz/artifacts/"
    echo "       input kept: $BUILD/fuzz/artifacts/$(basename "$a")"
done
exit 1
