#!/bin/sh
# End-to-end tests of `obscura bake`: the aalborg fixture of tests/data
# baked to .glb and PLY with a report, the .glb checked chunk by chunk
# (tests/e2e/lib/glb_check.py) and read back through assimp (baked
# again), the same bytes for 1 and 2 threads, the Khronos validator when
# it is installed, clear errors for bad input and usage; a TORCS track of
# ../shared/data when present.
#
#   OBSCURA=build/obscura tests/e2e/bake.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
. tests/e2e/lib/common.sh

expect() {
    code=$1; what=$2; shift 3
    "$@" >"$T/out" 2>"$T/err"
    rc=$?
    if [ "$rc" -eq "$code" ]; then ok "$what"; else
        bad "$what (exit $rc, expected $code)"; sed 's/^/       /' "$T/err" | tail -5; fi
}
said() {
    if grep -q -- "$1" "$T/err" "$T/out"; then ok "message: $1"; else
        bad "message '$1' missing"; sed 's/^/       /' "$T/err" | tail -5; fi
}
field() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval('d'+sys.argv[2]))" "$@"; }

echo "e2e bake: $OBSCURA"
FIX=tests/data/levels/aalborg_cut.acc
expect 0 "bake the aalborg fixture" -- "$OBSCURA" bake "$FIX" -o "$T/a.glb" --ply "$T/a.ply" \
    --report "$T/a.json" --rays 64 --distances 2,300 --blend 0.03 --color -q
check "report: 811 triangles" "[ \"\$(field $T/a.json \"['counts']['triangles']\")\" = 811 ]"
check "report: 64 rays per sample" \
    "[ \"\$(field $T/a.json \"['counts']['rays']\")\" = \"\$((64 * \$(field $T/a.json \"['counts']['samples']\")))\" ]"
check "report: every stage timed" "field $T/a.json \"['seconds']['solve']\" >/dev/null"
expect 0 "the .glb's chunks, accessors and _AO values" -- python3 tests/e2e/lib/glb_check.py "$T/a.glb" 62
expect 0 "the .glb read back through assimp (baked again)" -- "$OBSCURA" bake "$T/a.glb" \
    -o "$T/b.glb" --report "$T/b.json" --rays 8 -q
check "read back: 811 triangles, 62 instances" \
    "[ \"\$(field $T/b.json \"['counts']['triangles']\")\" = 811 ] && [ \"\$(field $T/b.json \"['counts']['instances']\")\" = 62 ]"
check "PLY header" "head -c 200 $T/a.ply | grep -q 'property float quality'"

expect 0 "1 thread" -- "$OBSCURA" bake "$FIX" -o "$T/t1.glb" --rays 16 --threads 1 -q
expect 0 "2 threads" -- "$OBSCURA" bake "$FIX" -o "$T/t2.glb" --rays 16 --threads 2 -q
check "the same bytes whatever the thread count" "cmp -s $T/t1.glb $T/t2.glb"
expect 0 "another seed" -- "$OBSCURA" bake "$FIX" -o "$T/s2.glb" --rays 16 --seed 2 -q
check "another seed, other values" "! cmp -s $T/t1.glb $T/s2.glb"

if command -v gltf_validator >/dev/null 2>&1; then
    expect 0 "Khronos glTF validator" -- gltf_validator -m "$T/a.glb"
elif node -e "require('gltf-validator')" >/dev/null 2>&1; then
    cat >"$T/validate.js" <<'JS'
const v = require('gltf-validator'), fs = require('fs');
v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[2])))
  .then(r => { console.log(JSON.stringify(r.issues)); process.exit(r.issues.numErrors ? 1 : 0); });
JS
    expect 0 "Khronos glTF validator (npm gltf-validator)" -- node "$T/validate.js" "$T/a.glb"
else
    echo "  skip Khronos glTF validator: npm package gltf-validator not installed (offline)"
fi

echo "-- shards: --shard I/N then --merge"
expect 0 "unsharded, 24 rays" -- "$OBSCURA" bake "$FIX" -o "$T/whole.glb" --rays 24 --report "$T/whole.json" -q
for n in 1 3 4; do
    i=0; ok_shards=1
    while [ $i -lt $n ]; do
        "$OBSCURA" bake "$FIX" --shard $i/$n -o "$T/part$n.$i.bin" --rays 24 --threads 2 -q 2>"$T/err" || ok_shards=0
        i=$((i + 1))
    done
    check "$n shard(s) traced" "[ $ok_shards = 1 ]"
    # shell order: part$n.0 .. part$n.(n-1); the merge takes any order
    expect 0 "merge of $n shard(s)" -- "$OBSCURA" bake "$FIX" --merge $(ls -r "$T"/part$n.*.bin) \
        -o "$T/merged$n.glb" --report "$T/merged$n.json" -q
    check "merged of $n = unsharded, byte for byte" "cmp -s $T/whole.glb $T/merged$n.glb"
    check "merged of $n: the rays of the unsharded bake" \
        "[ \"\$(field $T/merged$n.json \"['counts']['rays']\")\" = \"\$(field $T/whole.json \"['counts']['rays']\")\" ]"
    check "merged of $n: the parts' rays (24) in the report" "[ \"\$(field $T/merged$n.json \"['params']['rays']\")\" = 24 ]"
done
check "a part is 128 + 9 bytes a sample" \
    "[ \$((\$(cat $T/part3.*.bin | wc -c) - 3 * 128)) = \$((9 * \$(field $T/whole.json \"['counts']['samples']\"))) ]"
expect 3 "a missing shard" -- "$OBSCURA" bake "$FIX" --merge "$T/part4.0.bin" "$T/part4.1.bin" "$T/part4.3.bin" -o "$T/x.glb" -q
said "1 of 4 shards missing (2)"
expect 3 "a shard twice" -- "$OBSCURA" bake "$FIX" --merge "$T/part3.0.bin" "$T/part3.1.bin" "$T/part3.1.bin" -o "$T/x.glb" -q
said "shard 1/3 given twice"
expect 3 "shards of two splits" -- "$OBSCURA" bake "$FIX" --merge "$T/part3.0.bin" "$T/part4.1.bin" "$T/part3.2.bin" -o "$T/x.glb" -q
said "parts of different splits"
head -c 1000 "$T/part3.1.bin" >"$T/cut.bin"
expect 3 "a truncated part" -- "$OBSCURA" bake "$FIX" --merge "$T/part3.0.bin" "$T/cut.bin" "$T/part3.2.bin" -o "$T/x.glb" -q
said "truncated: 1000 bytes"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$T/tri.obj"
expect 0 "a shard of another level" -- "$OBSCURA" bake "$T/tri.obj" --shard 0/1 -o "$T/tri.bin" --rays 24 -q
i=0; ok_shards=1
while [ $i -lt 8 ]; do
    "$OBSCURA" bake "$T/tri.obj" --shard $i/8 -o "$T/tri8.$i.bin" --rays 24 -q 2>"$T/err" || ok_shards=0
    i=$((i + 1))
done
expect 0 "8 shards of a level of 4 samples (4 of them empty) merged" -- "$OBSCURA" bake "$T/tri.obj" \
    --merge "$T"/tri8.*.bin -o "$T/tri8.glb" -q
"$OBSCURA" bake "$T/tri.obj" -o "$T/tri1.glb" --rays 24 -q
check "... = unsharded, the empty parts 128 bytes" \
    "[ $ok_shards = 1 ] && cmp -s $T/tri1.glb $T/tri8.glb && [ \$(wc -c < $T/tri8.7.bin) = 137 ] && [ \$(wc -c < $T/tri8.0.bin) = 128 ]"
expect 3 "a part of another level" -- "$OBSCURA" bake "$FIX" --merge "$T/tri.bin" -o "$T/x.glb" -q
said "traced from another level"
expect 3 "not a part" -- "$OBSCURA" bake "$FIX" --merge "$T/whole.json" -o "$T/x.glb" -q
said "not a bake part"
expect 3 "a merge asking for other rays" -- "$OBSCURA" bake "$FIX" --merge "$T"/part1.0.bin -o "$T/x.glb" --rays 8 -q
said "traced with rays 24; this merge asks for 8"
expect 2 "--shard 4/4" -- "$OBSCURA" bake "$FIX" --shard 4/4 -o "$T/x.bin"
said "0 <= I < N"
expect 2 "--merge without parts" -- "$OBSCURA" bake "$FIX" --merge -o "$T/x.glb"
said "needs the part files"

echo "-- bad input"
for f in no_triangles.obj:"no triangles" nan_vertex.obj:"not finite" \
         huge_index_count.glb:"out of range" degenerate.obj:"degenerate"; do
    expect 3 "refuses ${f%%:*}" -- "$OBSCURA" bake "tests/data/levels/bad/${f%%:*}" -o "$T/x.glb" -q
    said "${f#*:}"
done
expect 3 "a missing file" -- "$OBSCURA" bake "$T/none.glb" -o "$T/x.glb" -q
said "cannot open"
expect 3 "max-triangles" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --max-triangles 10 -q
said "max_triangles"
expect 2 "--distances with one number" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --distances 2
said "SHORT,LONG"
expect 2 "a blend out of range" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --blend 2
said "blend"
expect 2 "an output of unknown format" -- "$OBSCURA" bake "$FIX" -o "$T/x.txt"
said ".glb or .ply"
expect 2 "an unknown option" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --nope 1
expect 0 "--params" -- "$OBSCURA" bake --params
said "backface-limit"

L="$SHARED/levels/torcs/aalborg/aalborg.acc"
if [ -f "$L" ]; then
    echo "-- aalborg (shared data)"
    expect 0 "bake aalborg" -- "$OBSCURA" bake "$L" -o "$T/aalborg.glb" --rays 16 --report "$T/aalborg.json" -q
    check "aalborg: 11,698 triangles, 1,315 instances" \
        "[ \"\$(field $T/aalborg.json \"['counts']['triangles']\")\" = 11698 ] && [ \"\$(field $T/aalborg.json \"['counts']['instances']\")\" = 1315 ]"
    expect 0 "aalborg .glb checked" -- python3 tests/e2e/lib/glb_check.py "$T/aalborg.glb" 1315
    for i in 0 1 2; do
        "$OBSCURA" bake "$L" --shard $i/3 -o "$T/aal.$i.bin" --rays 16 -q 2>"$T/err"
    done
    expect 0 "aalborg: merge of 3 shards" -- "$OBSCURA" bake "$L" --merge "$T"/aal.*.bin -o "$T/aal_merged.glb" -q
    check "aalborg: merged of 3 = unsharded, byte for byte" "cmp -s $T/aalborg.glb $T/aal_merged.glb"
else
    echo "  skip aalborg: $L absent (shared data)"
fi

echo "e2e bake: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
