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
else
    echo "  skip aalborg: $L absent (shared data)"
fi

echo "e2e bake: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
