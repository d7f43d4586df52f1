#!/bin/sh
# Writes the AO EXRs and PNGs of the bundled frames (room_small, yard_small,
# deep_small) through every path: in process on GL, the CPU twin, and an
# obscurad over HTTP, the Unix socket and TCP; then a static bake, a
# sharded static bake merged and a dynamic-object bake (whole and merged)
# of the bundled level.  Run it with two builds and
# compare the folders (`cmp`): a refactor that changes no behaviour changes
# no byte.
#
#   tools/same_bytes.sh OBSCURA OBSCURAD OUTDIR [BEFOREDIR]
#   tools/same_bytes.sh build/obscura build/obscurad /tmp/after /tmp/before
#
# With BEFOREDIR, every file of it is compared with OUTDIR's (cmp): the
# count of files compared and of those that differ is printed, and the
# exit status is 1 when any differs or is missing.
set -eu
OBSCURA=$1
OBSCURAD=$2
OUT=$3
BEFORE=${4:-}
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
# The bakes: a static bake (with LODs, a PLY and the decorators file), the
# same level over three shards merged, and a dynamic-object bake, whole and
# over two shards merged (the part files carry a run identifier, so they
# stay in the temporary folder).
L=tests/data/levels/aalborg_cut.acc
"$OBSCURA" bake "$L" -o "$OUT/bake.glb" --ply "$OUT/bake.ply" --rays 24 -q
"$OBSCURA" bake "$L" -o "$OUT/bake.lods.glb" --rays 24 --lods 2 -q
"$OBSCURA" bake "$L" -o "$OUT/bake.decor.glb" --decorators tests/data/levels/aalborg_cut.trees.json --rays 24 -q
for i in 0 1 2; do "$OBSCURA" bake "$L" --shard $i/3 -o "$T/bake.part$i.bin" --rays 24 -q; done
"$OBSCURA" bake "$L" --merge "$T"/bake.part*.bin -o "$OUT/bake.merged.glb" -q
DYN="--rays 32 --max-regions 12 -q"
"$OBSCURA" bake-dynamic "$L" -o "$OUT/dynamic.json" $DYN
for i in 0 1; do "$OBSCURA" bake-dynamic "$L" --shard $i/2 -o "$T/dynamic.part$i.bin" $DYN; done
"$OBSCURA" bake-dynamic "$L" --merge "$T"/dynamic.part*.bin -o "$OUT/dynamic.merged.json" $DYN
echo "same_bytes: $(ls "$OUT" | wc -l) files in $OUT"
[ -z "$BEFORE" ] && exit 0
n=0; bad=0
for f in "$BEFORE"/*; do
    n=$((n + 1))
    cmp -s "$f" "$OUT/${f##*/}" || { echo "same_bytes: differs: ${f##*/}" >&2; bad=$((bad + 1)); }
done
echo "same_bytes: $n files compared with $BEFORE, $bad differ"
[ "$bad" -eq 0 ]
