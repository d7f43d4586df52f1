#!/bin/sh
# Writes the AO EXRs and PNGs of the bundled frames (room_small, yard_small,
# deep_small) through every path: in process on GL, the CPU twin, and an
# obscurad over HTTP, the Unix socket and TCP.  Run it with two builds and
# compare the folders (`cmp`): a refactor that changes no behaviour changes
# no byte.
#
#   tools/same_bytes.sh OBSCURA OBSCURAD OUTDIR
#   tools/same_bytes.sh build/obscura build/obscurad /tmp/after
#   for f in /tmp/before/*; do cmp "$f" "/tmp/after/${f##*/}"; done
set -eu
OBSCURA=$1
OBSCURAD=$2
OUT=$3
D=tests/data
mkdir -p "$OUT"
T=$(mktemp -d)
PID=""
trap '[ -n "$PID" ] && kill "$PID" 2>/dev/null; rm -rf "$T"' EXIT

: > "$T/d.log"
"$OBSCURAD" --http 127.0.0.1:0 --socket "$T/s.sock" --tcp 127.0.0.1:0 --max-body 16m --queue 4 2>"$T/d.log" &
PID=$!
HP=""; TP=""; i=0
while [ $i -lt 300 ] && { [ -z "$HP" ] || [ -z "$TP" ] || [ ! -S "$T/s.sock" ]; }; do
    HP=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    TP=$(sed -n 's/.*binary protocol on tcp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    sleep 0.1; i=$((i + 1))
done
[ -n "$HP" ] && [ -n "$TP" ] || { echo "same_bytes: obscurad did not start" >&2; cat "$T/d.log" >&2; exit 1; }

# run NAME ARGS...: the frame in process, on the CPU twin and over each transport.
run() {
    name=$1; shift
    "$OBSCURA" ao "$@" -o "$OUT/$name.local.exr" -q
    "$OBSCURA" ao "$@" -o "$OUT/$name.local.png" -q
    for url in "http://127.0.0.1:$HP" "unix:$T/s.sock" "tcp://127.0.0.1:$TP"; do
        tag=${url%%:*}
        "$OBSCURA" ao "$@" -o "$OUT/$name.$tag.exr" --server "$url" -q
    done
}
for s in room_small yard_small; do
    run "$s" "$D/$s.exr" --camera "$D/$s.camera.json" --output both
    "$OBSCURA" ao "$D/$s.exr" --camera "$D/$s.camera.json" --output ao,composite,samples,cull,bleed,luminance \
        --float -o "$OUT/$s.all.exr" -q
    for m in hemisphere angle hbao gtao vao; do
        run "$s.$m" "$D/$s.exr" --camera "$D/$s.camera.json" --method $m
        "$OBSCURA" ao "$D/$s.exr" --camera "$D/$s.camera.json" --method $m --float -o "$OUT/$s.$m.float.exr" -q
    done
    "$OBSCURA" ao "$D/$s.exr" --camera "$D/$s.camera.json" --output both --cpu -o "$OUT/$s.cpu.exr" -q
    for m in hemisphere angle hbao gtao; do
        "$OBSCURA" ao "$D/$s.exr" --camera "$D/$s.camera.json" --method $m --cpu -o "$OUT/$s.$m.cpu.exr" -q
    done
done
run deep "$D/deep_small.exr" --output both --deep-layers 3
run deep.single "$D/deep_small.exr" --deep-mode single --deep-hull thin
"$OBSCURA" ao "$D/deep_small.exr" --output both --deep-layers 3 --cpu -o "$OUT/deep.cpu.exr" -q
run deep.hemisphere "$D/deep_small.exr" --method hemisphere --deep-hull thin
"$OBSCURA" ao "$D/deep_small.exr" --method hemisphere --float -o "$OUT/deep.hemisphere.float.exr" -q
"$OBSCURA" ao "$D/deep_small.exr" --method hemisphere --deep-hull thin --cpu -o "$OUT/deep.hemisphere.cpu.exr" -q
echo "same_bytes: $(ls "$OUT" | wc -l) files in $OUT"
