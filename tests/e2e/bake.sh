#!/bin/sh
# End-to-end tests of `obscura bake`: the aalborg fixture of tests/data
# baked to .glb and PLY with a report, the .glb checked chunk by chunk
# (tests/e2e/lib/glb_check.py) and read back through assimp (baked
# again), `obscura gbuffer` of the .glb (the baked channels, against the
# level's own G-buffer and the obscurance reference), `obscura ao` with
# the baked channel (--baked, --baked-combine), the same bytes for 1 and 2
# threads, --lods 2 (the LOD nodes read back, the report's levels, the
# file's own MSFT_lod levels read on a re-bake), the Khronos validator when
# it is installed, clear errors for bad input and usage; instanced trees
# (section 2.2) on a generated 4-tree level (lib/trees_fixture.py); a
# TORCS track of ../shared/data when present.
#
#   OBSCURA=build/obscura tests/e2e/bake.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
. tests/e2e/lib/common.sh
SAID_ERR_ONLY=1

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

echo "-- LODs: --lods 2 (meshoptimizer's levels, the bake resampled onto them and fitted, MSFT_lod)"
expect 0 "bake --lods 2 --lod-check 1" -- "$OBSCURA" bake "$FIX" -o "$T/lod.glb" --report "$T/lod.json" \
    --rays 32 --lods 2 --lod-check 1
said "LOD 2: "
expect 0 "the same bake without LODs" -- "$OBSCURA" bake "$FIX" -o "$T/nolod.glb" --report "$T/nolod.json" --rays 32 -q
check "the full detail is the bake without LODs (same residuals)" \
    "[ \"\$(field $T/lod.json \"['residual_rms']\")\" = \"\$(field $T/nolod.json \"['residual_rms']\")\" ]"
check "report: 2 levels, fewer triangles level by level, the lod stage timed" \
    "field $T/lod.json \"['lods']['per_level'][1]['triangles']\" >/dev/null && python3 -c \"
import json, sys; d = json.load(open('$T/lod.json')); l = d['lods']['per_level']
sys.exit(not (d['lods']['levels'] == 2 and len(l) == 2 and 0 < l[1]['triangles'] < l[0]['triangles'] < d['counts']['triangles'] and d['seconds']['lod'] > 0 and l[1]['samples'] > 0))\""
# against the bake made directly on the LOD geometry (traced there, fitted):
# the resampled fit nearer than sampling at the LOD's vertices (aalborg
# fixture, 32 rays: 0.031 / 0.036 at level 1, 0.040 / 0.051 at level 2)
for k in 0 1; do
    check "LOD $((k + 1)): fit nearer the direct LOD bake than vertex sampling (long)" "python3 -c \"
import json, sys; r = json.load(open('$T/lod.json'))['lods']['per_level'][$k]['direct_bake_rms']
sys.exit(not (r['least_squares']['long'] < r['vertex_sample']['long']))\""
done
expect 0 "the --lods .glb: each node's 2 LOD nodes with _AO, _AO_SHORT, _AO_LONG (glb_check --lods 2)" -- \
    python3 tests/e2e/lib/glb_check.py "$T/lod.glb" 186 --lods 2
expect 1 "... and glb_check tells a .glb without them" -- python3 tests/e2e/lib/glb_check.py "$T/nolod.glb" 62 --lods 2
expect 0 "the --lods .glb read back through assimp (LOD nodes outside the scene)" -- "$OBSCURA" bake \
    "$T/lod.glb" -o "$T/lod_b.glb" --report "$T/lod_b.json" --rays 8 -q
check "read back: 811 triangles, 62 instances" \
    "[ \"\$(field $T/lod_b.json \"['counts']['triangles']\")\" = 811 ] && [ \"\$(field $T/lod_b.json \"['counts']['instances']\")\" = 62 ]"
echo "-- a file's own LODs (MSFT_lod): the --lods .glb baked again"
expect 0 "re-bake of the --lods .glb with --lods 2 --lod-ratio 0.3 (lod_source file)" -- "$OBSCURA" bake \
    "$T/lod.glb" -o "$T/lodf.glb" --report "$T/lodf.json" --rays 16 --lods 2 --lod-ratio 0.3 -q
check "the file's levels used as they are: 62 meshes a level from the file, the first bake's triangles" "python3 -c \"
import json, sys; a = json.load(open('$T/lod.json'))['lods']['per_level']; b = json.load(open('$T/lodf.json'))['lods']['per_level']
sys.exit(not all(y['meshes_from_file'] == 62 and y['triangles'] == x['triangles'] for x, y in zip(a, b)))\""
expect 0 "the re-baked .glb keeps its 2 LOD nodes a node" -- python3 tests/e2e/lib/glb_check.py "$T/lodf.glb" 186 --lods 2
expect 0 "--lod-source simplify: simplified again" -- "$OBSCURA" bake "$T/lod.glb" -o "$T/lods.glb" \
    --report "$T/lods.json" --rays 16 --lods 2 --lod-ratio 0.3 --lod-source simplify -q
check "... at ratio 0.3: fewer triangles than the file's, none from the file" "python3 -c \"
import json, sys; a = json.load(open('$T/lod.json'))['lods']['per_level']; b = json.load(open('$T/lods.json'))['lods']['per_level']
sys.exit(not all(y['meshes_from_file'] == 0 and y['triangles'] < x['triangles'] for x, y in zip(a, b)))\""
expect 0 "--lod-lock-border 1: the meshes' open borders kept at every level" -- "$OBSCURA" bake "$FIX" \
    -o "$T/lodlock.glb" --report "$T/lodlock.json" --rays 8 --lods 2 --lod-lock-border 1 -q
expect 0 "... each level has no more triangles than the one above it (glb_check --lods 2)" -- \
    python3 tests/e2e/lib/glb_check.py "$T/lodlock.glb" 186 --lods 2
check "... and more triangles than the free borders' levels, fewer than the full detail" "python3 -c \"
import json, sys; a = json.load(open('$T/lod.json')); b = json.load(open('$T/lodlock.json'))
f, k = a['lods']['per_level'], b['lods']['per_level']
sys.exit(not all(x['triangles'] < y['triangles'] < b['counts']['triangles'] for x, y in zip(f, k)))\""
python3 tests/e2e/lib/glb_edit.py "$T/lod.glb" "$T/lodmove.glb" lodmove
python3 tests/e2e/lib/glb_edit.py "$T/lod.glb" "$T/lodprims.glb" lodprims
expect 3 "a LOD node moved against its node, with --lods" -- "$OBSCURA" bake "$T/lodmove.glb" -o "$T/x.glb" --lods 1 -q
said "has another transform than its node"
expect 0 "... baked without --lods" -- "$OBSCURA" bake "$T/lodmove.glb" -o "$T/x.glb" --rays 4 -q
expect 0 "... or with --lod-source simplify" -- "$OBSCURA" bake "$T/lodmove.glb" -o "$T/x.glb" --rays 4 --lods 1 --lod-source simplify -q
expect 3 "a LOD node whose mesh lacks a primitive" -- "$OBSCURA" bake "$T/lodprims.glb" -o "$T/x.glb" --lods 1 -q
said "primitives like its node's"
python3 tests/e2e/lib/glb_edit.py "$T/lod.glb" "$T/lodcount.glb" lodcount
expect 3 "a LOD accessor beyond its view" -- "$OBSCURA" bake "$T/lodcount.glb" -o "$T/x.glb" --lods 1 -q
said "out of range of its view"
expect 0 "--lods 2, 1 thread" -- "$OBSCURA" bake "$FIX" -o "$T/lod_t1.glb" --rays 16 --lods 2 --threads 1 -q
expect 0 "--lods 2, 2 threads" -- "$OBSCURA" bake "$FIX" -o "$T/lod_t2.glb" --rays 16 --lods 2 --threads 2 -q
check "LODs: the same bytes whatever the thread count" "cmp -s $T/lod_t1.glb $T/lod_t2.glb"
expect 2 "--lods with a .ply output" -- "$OBSCURA" bake "$FIX" -o "$T/x.ply" --lods 1
said "a .ply has no LODs"
expect 2 "--lods 9" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --lods 9
said "lods"
expect 2 "--lod-ratio 1" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --lods 1 --lod-ratio 1
said "lod_ratio"

# The Khronos validator from npm, installed once into build/npm when npm
# reaches its registry; skipped (saying so) when it cannot.
NPM_DIR=build/npm
if ! command -v gltf_validator >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 &&
    [ ! -d "$NPM_DIR/node_modules/gltf-validator" ]; then
    mkdir -p "$NPM_DIR"
    timeout 180 npm install --prefix "$NPM_DIR" --no-audit --no-fund --silent gltf-validator \
        >"$T/npm.log" 2>&1 || echo "  (npm install gltf-validator failed: $(tail -1 "$T/npm.log"))"
fi
export NODE_PATH="$PWD/$NPM_DIR/node_modules${NODE_PATH:+:$NODE_PATH}"
echo "-- decorators (section 2.2): the fixture's two tree cards from a trees.json cut"
TREES=tests/data/levels/aalborg_cut.trees.json
expect 0 "bake with --decorators (trees.json's layout)" -- "$OBSCURA" bake "$FIX" -o "$T/dt.glb" \
    --rays 16 --decorators "$TREES" --report "$T/dt.json" -q
check "report: 2 tree nodes, 60 opaque" \
    "[ \"\$(field $T/dt.json \"['decorator_nodes']['tree']\")\" = 2 ] && [ \"\$(field $T/dt.json \"['decorator_nodes']['none']\")\" -gt 55 ]"
check "the trees semi-transparent: other values" "! cmp -s $T/t1.glb $T/dt.glb"
printf '{"decorators": [{"name": "OBJ1479", "class": "tree"}, {"name": "OBJ1478", "class": "shrub"}]}\n' >"$T/mixed.json"
expect 0 "a tree and a shrub, 1 thread" -- "$OBSCURA" bake "$FIX" -o "$T/dm1.glb" --rays 16 \
    --threads 1 --decorators "$T/mixed.json" -q
expect 0 "a tree and a shrub, 2 threads" -- "$OBSCURA" bake "$FIX" -o "$T/dm2.glb" --rays 16 \
    --threads 2 --decorators "$T/mixed.json" -q
check "decorators: the same bytes whatever the thread count" "cmp -s $T/dm1.glb $T/dm2.glb"
expect 0 "--tree-attenuation 1 (each card blocks all)" -- "$OBSCURA" bake "$FIX" -o "$T/dt1.glb" \
    --rays 16 --decorators "$TREES" --tree-attenuation 1 -q
check "... other values again" "! cmp -s $T/dt.glb $T/dt1.glb"
expect 0 "--decorator-source off: the file is not used" -- "$OBSCURA" bake "$FIX" -o "$T/doff.glb" \
    --rays 16 --decorators "$TREES" --decorator-source off -q
check "... the same bytes as without decorators" "cmp -s $T/t1.glb $T/doff.glb"
printf '{"decorators": [{"match": "OBJ147*", "class": "shrub", "density": 0.5}]}\n' >"$T/shrub.json"
expect 0 "the cards as shrubs (fog boxes)" -- "$OBSCURA" bake "$FIX" -o "$T/ds.glb" --rays 16 \
    --decorators "$T/shrub.json" --report "$T/ds.json" -q
check "report: shrub nodes" "[ \"\$(field $T/ds.json \"['decorator_nodes']['shrub']\")\" -ge 2 ]"
printf '{"decorators": [{"name": "OBJ1479", "class": "small"}]}\n' >"$T/small.json"
expect 0 "a card as a small decorator (section 2.2.1)" -- "$OBSCURA" bake "$FIX" -o "$T/dm.glb" \
    --rays 16 --decorators "$T/small.json" --report "$T/dm.json" -q
check "report: one small decorator's scalar" \
    "[ \"\$(field $T/dm.json \"['small_decorators']['nodes'][0]['name']\")\" = OBJ1479 ]"
check "the .glb: the scalar in the node's extras" \
    "python3 -c \"import json,struct,sys; b=open(sys.argv[1],'rb').read(); n=struct.unpack('<I',b[12:16])[0]; j=json.loads(b[20:20+n]); sys.exit(not [x for x in j['nodes'] if x.get('name')=='OBJ1479' and '_AO' in x.get('extras',{})])\" $T/dm.glb"
printf '{"decorators": [{"name": "OBJ1479", "class": "palm"}]}\n' >"$T/bad_class.json"
expect 3 "a decorators file with an unknown class" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" \
    --decorators "$T/bad_class.json"
said "unknown class 'palm'"
printf '{"decorators": [{"name": "OBJ1479", "class": "tree"}' >"$T/bad_json.json"
expect 3 "a decorators file that is not JSON" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" \
    --decorators "$T/bad_json.json"
said "not JSON"
expect 3 "a decorators file that is not there" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" \
    --decorators "$T/none.json"
said "cannot open"
printf '{"trees": [{"name": "OBJ1479"}, {"name": "OBJ0000"}]}\n' >"$T/unmatched.json"
expect 0 "entries matching no node: a warning" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --rays 8 \
    --decorators "$T/unmatched.json" -q
said "1 of 2 entries match no node (the first: 'OBJ0000')"

if command -v gltf_validator >/dev/null 2>&1; then
    expect 0 "Khronos glTF validator" -- gltf_validator -m "$T/a.glb"
    expect 0 "Khronos glTF validator: the --lods .glb" -- gltf_validator -m "$T/lod.glb"
elif node -e "require('gltf-validator')" >/dev/null 2>&1; then
    cat >"$T/validate.js" <<'JS'
const v = require('gltf-validator'), fs = require('fs');
v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[2])))
  .then(r => { const i = r.issues;
    console.log(`${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos`);
    if (i.numErrors || i.numWarnings) console.log(JSON.stringify(i.messages));
    process.exit(i.numErrors || i.numWarnings ? 1 : 0); });
JS
    for g in a b lod lodf; do
        expect 0 "Khronos glTF validator (npm gltf-validator): $g.glb, no errors or warnings" -- \
            node "$T/validate.js" "$T/$g.glb"
    done
else
    echo "  skip Khronos glTF validator: gltf_validator not on PATH and npm could not install gltf-validator (offline?)"
fi

for v in face_mean:face_mean point:point_sample; do
    expect 0 "--values ${v%%:*} (a baseline written)" -- "$OBSCURA" bake "$FIX" -o "$T/v.glb" \
        --rays 16 --values ${v%%:*} --report "$T/v.json" -q
    check "${v%%:*}: the written values' residual is the baseline's" \
        "[ \"\$(field $T/v.json \"['residual_rms']['least_squares']\")\" = \"\$(field $T/v.json \"['residual_rms']['${v#*:}']\")\" ]"
    check "${v%%:*}: other values than the fit's" "! cmp -s $T/t1.glb $T/v.glb"
done
expect 2 "--values of no kind" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --values mean
said "fit|face_mean|point"

echo "-- gbuffer of the baked .glb: _AO, _AO_SHORT, _AO_LONG as channels"
json() { sed -n "s/.*\"$1\": \([-0-9.e+]*\).*/\1/p" "$T/out"; }
expect 0 "cameras from the level's vertices" -- python3 tools/level_cameras.py "$T/a.glb" "$T" 2 160 120
expect 0 "gbuffer a.glb (baked, found by its attributes)" -- "$OBSCURA" gbuffer "$T/a.glb" \
    --camera "$T/cam0.json" -o "$T/g.exr"
said "baked _AO, _AO_SHORT, _AO_LONG"
expect 0 "_AO = 0.03 _AO_SHORT + 0.97 _AO_LONG, interpolated" -- "$OBSCURA" compare "$T/g.exr" \
    "$T/g.exr" --channel-a _AO_LONG --channel-b _AO --json
b1=$(json bias)
expect 0 "_AO_SHORT against _AO_LONG" -- "$OBSCURA" compare "$T/g.exr" "$T/g.exr" \
    --channel-a _AO_LONG --channel-b _AO_SHORT --json
b2=$(json bias)
check "bias(_AO - long) $b1 = 0.03 bias(short - long) $b2" \
    "awk 'BEGIN { d = $b1 - 0.03 * $b2; exit !(d < 1e-5 && d > -1e-5 && ($b2 > 0.005 || $b2 < -0.005)) }'"
expect 0 "gbuffer of the --lods .glb" -- "$OBSCURA" gbuffer "$T/lod.glb" --camera "$T/cam0.json" -o "$T/g_lod.exr" -q
expect 0 "gbuffer of the same bake without LODs" -- "$OBSCURA" gbuffer "$T/nolod.glb" --camera "$T/cam0.json" \
    -o "$T/g_nolod.exr" -q
for ch in A _AO N.Y; do
    expect 0 "--lods .glb against the one without: $ch" -- "$OBSCURA" compare "$T/g_nolod.exr" "$T/g_lod.exr" \
        --channel-a $ch --channel-b $ch --json
    m=$(json mse)
    check "the LOD nodes outside the scene are not drawn: $ch MSE $m = 0" "awk 'BEGIN { exit !($m == 0) }'"
done
echo "-- obscura ao with the baked channel (screen-space x baked)"
expect 0 "ao on the baked G-buffer: _AO found by name" -- "$OBSCURA" ao "$T/g.exr" -o "$T/c.exr" --radius 2
said "baked channel _AO combined (product)"
expect 0 "AO.Y (product) against AOScreen.Y" -- "$OBSCURA" compare "$T/c.exr" "$T/c.exr" \
    --channel-a AOScreen.Y --channel-b AO.Y --json
b1=$(json bias)
check "the product is darker than the chain's AO: bias $b1 < 0" "awk 'BEGIN { exit !($b1 < 0) }'"
expect 0 "AOBaked.Y is the G-buffer's _AO" -- "$OBSCURA" compare "$T/g.exr" "$T/c.exr" \
    --channel-a _AO --channel-b AOBaked.Y --json
m=$(json mse)
check "AOBaked.Y = _AO: MSE $m < 1e-6 (half floats)" "awk 'BEGIN { exit !($m < 1e-6) }'"
expect 0 "--baked _AO_LONG --baked-combine min" -- "$OBSCURA" ao "$T/g.exr" -o "$T/cmin.exr" \
    --radius 2 --baked _AO_LONG --baked-combine min
expect 0 "--baked _AO_LONG (product)" -- "$OBSCURA" ao "$T/g.exr" -o "$T/cprod.exr" \
    --radius 2 --baked _AO_LONG
expect 0 "min against product" -- "$OBSCURA" compare "$T/cprod.exr" "$T/cmin.exr" --json
b2=$(json bias)
check "min(s, b) >= s b: bias $b2 > 0" "awk 'BEGIN { exit !($b2 > 0) }'"
expect 0 "--baked none: the chain's AO alone" -- "$OBSCURA" ao "$T/g.exr" -o "$T/cnone.exr" \
    --radius 2 --baked none
expect 3 "... so no AOBaked.Y" -- "$OBSCURA" compare "$T/cnone.exr" "$T/cnone.exr" \
    --channel-a AOBaked.Y --channel-b AO.Y
expect 0 "--baked none equals AOScreen.Y" -- "$OBSCURA" compare "$T/cnone.exr" "$T/c.exr" \
    --channel-b AOScreen.Y --json
m=$(json mse)
check "MSE $m = 0" "awk 'BEGIN { exit !($m == 0) }'"
if [ -x "${OBSCURAD:-build/obscurad}" ]; then
    OBSCURAD=${OBSCURAD:-build/obscurad}
    start D --socket "$T/d.sock"
    expect 0 "ao --server with the baked channel (combined here)" -- "$OBSCURA" ao "$T/g.exr" \
        -o "$T/cr.exr" --radius 2 --server "unix:$T/d.sock"
    expect 0 "the remote combination against the in-process one" -- "$OBSCURA" compare \
        "$T/c.exr" "$T/cr.exr" --json
    m=$(json mse)
    check "remote = in process: MSE $m < 1e-6" "awk 'BEGIN { exit !($m < 1e-6) }'"
    expect 0 "... AOBaked.Y there too" -- "$OBSCURA" compare "$T/c.exr" "$T/cr.exr" \
        --channel-a AOBaked.Y --channel-b AOBaked.Y
else
    echo "  skip ao --server: no obscurad built"
fi
expect 3 "--baked naming no channel" -- "$OBSCURA" ao "$T/g.exr" -o "$T/x.exr" --baked _AO_MID
said "channel '_AO_MID' not found"
expect 2 "--baked-combine of no kind" -- "$OBSCURA" ao "$T/g.exr" -o "$T/x.exr" --baked-combine sum
said "product|min"

expect 0 "gbuffer of the level itself (assimp)" -- "$OBSCURA" gbuffer "$FIX" \
    --camera "$T/cam0.json" -o "$T/g_level.exr" -q
for ch in N.Y N.X P.Y; do
    expect 0 "the baked .glb's $ch against the level's" -- "$OBSCURA" compare "$T/g_level.exr" \
        "$T/g.exr" --channel-a $ch --channel-b $ch --json
    m=$(json mse)
    check "$ch: MSE $m < 1e-4 (same triangles, same transforms)" "awk 'BEGIN { exit !($m < 1e-4) }'"
done
expect 0 "the obscurance reference of the same camera" -- "$OBSCURA" reference "$T/a.glb" \
    --camera "$T/cam0.json" -o "$T/r.exr" --obscurance 2,300 --blend 0.03 --spp 64 -q
expect 0 "baked _AO against the reference" -- "$OBSCURA" compare "$T/r.exr" "$T/g.exr" \
    --channel-b _AO --json
m=$(json mse); c=$(json corr)
check "baked vs reference: MSE $m < 0.02, corr $c > 0.6" "awk 'BEGIN { exit !($m < 0.02 && $c > 0.6) }'"
expect 0 "the reference's short distance against the baked long one" -- "$OBSCURA" compare \
    "$T/r.exr" "$T/g.exr" --channel-a AO_SHORT.Y --channel-b _AO_LONG --json
m2=$(json mse)
check "a mismatched channel is further: MSE $m2 > $m" "awk 'BEGIN { exit !($m2 > $m) }'"
expect 0 "gbuffer of the bake with decorators" -- "$OBSCURA" gbuffer "$T/dt.glb" \
    --camera "$T/cam0.json" -o "$T/gd.exr" -q
expect 0 "the reference with the same decorators" -- "$OBSCURA" reference "$T/a.glb" \
    --camera "$T/cam0.json" -o "$T/rd.exr" --obscurance 2,300 --blend 0.03 --spp 64 \
    --decorators "$TREES"
said "decorators traced as the bake does"
expect 0 "baked _AO (decorators) against that reference" -- "$OBSCURA" compare "$T/rd.exr" \
    "$T/gd.exr" --channel-b _AO --json
m=$(json mse); c=$(json corr)
check "decorators: baked vs reference: MSE $m < 0.02, corr $c > 0.6" \
    "awk 'BEGIN { exit !($m < 0.02 && $c > 0.6) }'"
expect 2 "reference --decorators without --obscurance" -- "$OBSCURA" reference "$T/a.glb" \
    --camera "$T/cam0.json" -o "$T/x.exr" --decorators "$TREES"
said "need --obscurance"
for e in trs matrix noao; do python3 tests/e2e/lib/glb_edit.py "$T/a.glb" "$T/$e.glb" $e; done
python3 tests/e2e/lib/glb_edit.py "$T/trs.glb" "$T/trs_noao.glb" noao
# the camera of the transformed level: cam0 moved by the same transform
python3 - "$T/cam0.json" "$T/camt.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
W = c["world_to_camera"]
# world' = T R S world: W' = W (T R S)^-1, (T R S)^-1 p = S^-1 R^-1 (p - t)
Minv = [[0, 0, -0.5, 0], [0, 0.5, 0, 0], [0.5, 0, 0, 0], [0, 0, 0, 1]]  # S^-1 R^T
t = [10, 2, -5]
Tinv = [[1, 0, 0, -t[0]], [0, 1, 0, -t[1]], [0, 0, 1, -t[2]], [0, 0, 0, 1]]
mul = lambda A, B: [[sum(A[i][k] * B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]
c["world_to_camera"] = mul(W, mul(Minv, Tinv))
json.dump(c, open(sys.argv[2], "w"))
PY
for e in trs matrix; do
    expect 0 "gbuffer of the baked level under a $e transform" -- "$OBSCURA" gbuffer "$T/$e.glb" \
        --camera "$T/camt.json" -o "$T/g_$e.exr" -q
done
expect 0 "the same through assimp (no _AO)" -- "$OBSCURA" gbuffer "$T/trs_noao.glb" \
    --camera "$T/camt.json" -o "$T/g_trs_assimp.exr" -q
# (compare clamps to [0, 1]: normals, coverage A and the baked values)
for pair in "g_trs g_matrix N.X N.Y N.Z A _AO" "g_trs_assimp g_trs N.X N.Y N.Z A" "g g_trs A _AO"; do
    set -- $pair
    x=$1; y=$2; shift 2
    for ch in "$@"; do
        expect 0 "$x against $y: $ch" -- "$OBSCURA" compare "$T/$x.exr" "$T/$y.exr" \
            --channel-a $ch --channel-b $ch --json
        m=$(json mse)
        check "$x vs $y $ch: MSE $m < 1e-4" "awk 'BEGIN { exit !($m < 1e-4) }'"
    done
done
expect 3 "gbuffer --baked of a .glb without _AO" -- "$OBSCURA" gbuffer "$T/noao.glb" --baked \
    --camera "$T/cam0.json" -o "$T/x.exr"
said "no _AO attribute"
expect 0 "without --baked the same file is an ordinary mesh" -- "$OBSCURA" gbuffer "$T/noao.glb" \
    --camera "$T/cam0.json" -o "$T/x.exr"
check "no baked channels then" "! grep -q 'baked _AO' $T/err"
head -c 3000 "$T/a.glb" > "$T/cut.glb"
expect 3 "a truncated baked .glb" -- "$OBSCURA" gbuffer "$T/cut.glb" --baked \
    --camera "$T/cam0.json" -o "$T/x.exr"
said "truncated"
expect 2 "--baked with --deep" -- "$OBSCURA" gbuffer "$T/a.glb" --baked --deep \
    --camera "$T/cam0.json" -o "$T/x.exr"

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
expect 0 "unsharded, 24 rays, --lods 2" -- "$OBSCURA" bake "$FIX" -o "$T/whole_lod.glb" --rays 24 --lods 2 -q
expect 0 "merge of 3 shards with --lods 2" -- "$OBSCURA" bake "$FIX" --merge "$T"/part3.*.bin \
    -o "$T/merged_lod.glb" --lods 2 -q
check "merged with --lods = unsharded with --lods, byte for byte" "cmp -s $T/whole_lod.glb $T/merged_lod.glb"
expect 0 "decorators: unsharded" -- "$OBSCURA" bake "$FIX" -o "$T/dwhole.glb" --rays 24 \
    --decorators "$TREES" -q
for i in 0 1; do
    "$OBSCURA" bake "$FIX" --shard $i/2 -o "$T/dpart.$i.bin" --rays 24 --decorators "$TREES" -q
done
expect 0 "decorators: merge of 2 shards" -- "$OBSCURA" bake "$FIX" --merge "$T"/dpart.*.bin \
    -o "$T/dmerged.glb" --decorators "$TREES" -q
check "decorators: merged = unsharded, byte for byte" "cmp -s $T/dwhole.glb $T/dmerged.glb"
expect 3 "decorators: parts merged without the decorators" -- "$OBSCURA" bake "$FIX" \
    --merge "$T"/dpart.*.bin -o "$T/x.glb" -q
said "with other decorators"
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

echo "-- instanced trees (section 2.2): local AO x linear global AO (eq 3)"
TREES="$T/trees.glb"
python3 tests/e2e/lib/trees_fixture.py "$TREES"
IT="--rays 32 --volume-rays 64 --volume-spacing 0.5 --distances 2,20 -q"
expect 0 "bake 4 instanced trees" -- "$OBSCURA" bake "$TREES" -o "$T/tr.glb" --report "$T/tr.json" $IT
check "report: 1 mesh baked alone, 4 instances fitted" \
    "[ \"\$(field $T/tr.json \"['instanced']['meshes']\")\" = 1 ] && [ \"\$(field $T/tr.json \"['instanced']['instances']\")\" = 4 ] && [ \"\$(field $T/tr.json \"['decorator_nodes']['tree']\")\" = 4 ]"
check "report: the volume's points and rays (64 each)" \
    "[ \"\$(field $T/tr.json \"['instanced']['volume_rays']\")\" = \"\$((64 * \$(field $T/tr.json \"['instanced']['volume_points']\")))\" ]"
check "report: 4 coefficient sets, stages local, volume, global timed" \
    "[ \"\$(field $T/tr.json \"['instanced']['list'].__len__()\")\" = 4 ] && field $T/tr.json \"['seconds']['global']\" >/dev/null"
expect 0 "the .glb: _AO = _AO_LOCAL x G(POSITION) from the node extras, 4 instanced" -- \
    python3 tests/e2e/lib/glb_check.py "$T/tr.glb" 6 4
expect 0 "instanced trees with --lods 1" -- "$OBSCURA" bake "$TREES" -o "$T/trl.glb" $IT --lods 1
expect 0 "their LODs show the instanced AO (each level's mean _AO within 0.05 of its mesh's)" -- \
    python3 tests/e2e/lib/glb_check.py "$T/trl.glb" 12 4 --lods 1 --lod-mean 0.05
# G at the tree's middle (0, 1, 0): under the roof darker than each in the open
check "the tree under the roof has the darkest global AO" "python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))[\"instanced\"][\"list\"]
g = {e[\"node\"]: e[\"global_ao\"][0] + e[\"global_ao\"][2] for e in d}
u = g.pop(\"palm_under_roof\")
sys.exit(0 if all(u < v - 0.05 for v in g.values()) else 1)' $T/tr.json"
expect 0 "instanced trees, 1 thread" -- "$OBSCURA" bake "$TREES" -o "$T/tr1.glb" $IT --threads 1
expect 0 "instanced trees, 2 threads" -- "$OBSCURA" bake "$TREES" -o "$T/tr2.glb" $IT --threads 2
check "instanced: the same bytes whatever the thread count" "cmp -s $T/tr1.glb $T/tr2.glb && cmp -s $T/tr.glb $T/tr1.glb"
for i in 0 1; do "$OBSCURA" bake "$TREES" --shard $i/2 -o "$T/trp.$i.bin" $IT 2>"$T/err"; done
expect 0 "instanced trees: merge of 2 shards" -- "$OBSCURA" bake "$TREES" --merge "$T"/trp.*.bin -o "$T/trm.glb" $IT
check "instanced: merged = unsharded, byte for byte" "cmp -s $T/tr.glb $T/trm.glb"
expect 0 "--instanced off" -- "$OBSCURA" bake "$TREES" -o "$T/troff.glb" --report "$T/troff.json" $IT --instanced off
check "--instanced off: no model, no _AO_LOCAL" \
    "[ \"\$(field $T/troff.json \"['instanced']['instances']\")\" = 0 ] && ! grep -q _AO_LOCAL $T/troff.glb"
expect 0 "--instanced off: the .glb checked" -- python3 tests/e2e/lib/glb_check.py "$T/troff.glb" 6 0
for v in linear local; do
    expect 0 "--instanced-values $v" -- "$OBSCURA" bake "$TREES" -o "$T/tr_$v.glb" $IT --instanced-values $v
    expect 0 "--instanced-values $v: _AO = _AO_LOCAL x G" -- python3 tests/e2e/lib/glb_check.py "$T/tr_$v.glb" 6 4
done
expect 0 "--instanced-values volume" -- "$OBSCURA" bake "$TREES" -o "$T/tr_volume.glb" $IT --instanced-values volume
expect 0 "--instanced-values volume: no model written, the .glb checked" -- \
    python3 tests/e2e/lib/glb_check.py "$T/tr_volume.glb" 6 0
check "--instanced-values: other values than the product" "! cmp -s $T/tr.glb $T/tr_linear.glb && ! cmp -s $T/tr.glb $T/tr_local.glb"
expect 0 "--instanced-min 5: the mesh has 4 tree nodes" -- "$OBSCURA" bake "$TREES" -o "$T/x.glb" \
    --report "$T/trmin.json" $IT --instanced-min 5
check "--instanced-min 5: nothing instanced" "[ \"\$(field $T/trmin.json \"['instanced']['instances']\")\" = 0 ]"
expect 3 "a volume too fine" -- "$OBSCURA" bake "$TREES" -o "$T/x.glb" $IT --volume-spacing 0.01
said "raise volume_spacing"
expect 2 "--volume-spacing 0" -- "$OBSCURA" bake "$TREES" -o "$T/x.glb" --volume-spacing 0
said "volume_spacing"
expect 2 "--instanced bushes" -- "$OBSCURA" bake "$TREES" -o "$T/x.glb" --instanced bushes
said "instanced"

echo "-- bad input"
for f in no_triangles.obj:"no triangles" nan_vertex.obj:"not finite" \
         huge_index_count.glb:"out of range" degenerate.obj:"degenerate" \
         coords_3e38.obj:"in world space: a coordinate beyond +-1e9"; do
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
