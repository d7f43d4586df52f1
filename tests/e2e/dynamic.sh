#!/bin/sh
# End-to-end tests of `obscura bake-dynamic`: the aalborg fixture of
# tests/data with built regions and with a regions file, the model file
# read back by an independent reader of its documented format
# (tests/e2e/lib/dyn_eval.py) against `--eval`, the same bytes for 1 and 2
# threads, the report's measures, the decorators traced as obscura bake
# traces them (none marked: the bytes of decorator-source off; a
# --decorators file or a node named tree: another model, brighter under a
# tree than under an opaque roof), the bake over shards (--shard I/N,
# --merge: merged = unsharded byte for byte, bad parts refused, parts
# traced with other decorators refused), `obscura
# gbuffer --dynamic` (a dynamic object in the baked level valued from the
# model per pixel, checked by the independent reader; the static pixels
# unchanged), clear errors for bad regions files, models and usage.
#
#   OBSCURA=build/obscura tests/e2e/dynamic.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
. tests/e2e/lib/common.sh
SAID_ERR_ONLY=1

echo "e2e bake-dynamic: $OBSCURA"
FIX=tests/data/levels/aalborg_cut.acc
FAST="--rays 64 --max-regions 24 -q"
expect 0 "bake-dynamic the aalborg fixture" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/m.json" \
    --report "$T/r.json" $FAST --holdout 0.2 --paths 6 --path-steps 32 --path-rays 64
check "report: 24 regions, 512 grid points each" \
    "[ \"\$(field $T/r.json \"['counts']['regions']\")\" = 24 ] && [ \"\$(field $T/r.json \"['counts']['grid_points']\")\" = 12288 ]"
check "report: some grid points inside geometry, most valid" \
    "python3 -c \"import json; c=json.load(open('$T/r.json'))['counts']; assert c['points_inside'] > 0 and c['points_valid'] > c['grid_points'] / 2\""
check "report: 64 rays per valid point" \
    "python3 -c \"import json; c=json.load(open('$T/r.json'))['counts']; assert c['rays'] == 64 * (c['points_valid'] + c['points_backface'])\""
check "held back: eq 4 beats a constant" \
    "python3 -c \"import json; h=json.load(open('$T/r.json'))['holdout_rms']; assert h['points'] > 0 and h['eq4'] < h['constant'], h\""
check "regularisation: smaller jumps at the boundaries, lower energy" \
    "python3 -c \"import json; j=json.load(open('$T/r.json'))['boundary_jump']; assert j['mean'][1] < j['mean'][0] and j['energy'][1] < j['energy'][0], j\""
check "paths: measured, blending lowers the crossing jumps" \
    "python3 -c \"import json; p=json.load(open('$T/r.json'))['paths']; assert p['points'] > 0 and p['crossings'] > 0 and p['regularised_blended']['crossing_mean'] < p['unregularised']['crossing_mean'], p\""
check "model file: format, one model per region or absorbed" \
    "python3 -c \"import json; d=json.load(open('$T/m.json')); assert d['format'] == 'obscura-dynamic-ao' and len(d['regions']) == 24 and all(r['model'] < len(d['models']) for r in d['regions']) and all(len(m['coefficients']) == 18 and all(len(c) == 7 for c in m['coefficients']) for m in d['models'])\""

# --eval against an independent reader of the documented file format, at
# points inside regions and outside every box, both SH orders.
n=0
for spec in "0.3,0.6,0.2:0,1,0:quadratic" "0.7,0.2,0.9:0.6,0,0.8:linear" "0.5,0.5,0.5:-1,0,0:quadratic" \
            "-2,0.5,3:0,0,1:quadratic" "0.1,0.9,0.4:0,-1,0:linear"; do
    rel=${spec%%:*}; rest=${spec#*:}; nrm=${rest%%:*}; sh=${rest#*:}
    at=$(python3 -c "
import json,sys; d=json.load(open('$T/m.json')); r=[g for g in d['regions'] if g['model']>=0][3]
f=[float(x) for x in '$rel'.split(',')]
print(','.join(repr(r['min'][a]+(r['max'][a]-r['min'][a])*f[a]) for a in range(3)))")
    expect 0 "--eval at $at ($sh)" -- "$OBSCURA" bake-dynamic --eval "$T/m.json" --at "$at" --normal "$nrm" --sh "$sh"
    got=$(cat "$T/out")
    want=$(python3 tests/e2e/lib/dyn_eval.py "$T/m.json" "$at" "$nrm" "$sh")
    check "--eval $got = the reader's $want" "python3 -c 'import sys; sys.exit(abs($got - $want) > 2e-5)'"
    n=$((n + 1))
done
"$OBSCURA" bake-dynamic --eval "$T/m.json" --at 0.5,5,-690 --normal 0,1,0 --sh linear >"$T/lin" 2>/dev/null
"$OBSCURA" bake-dynamic --eval "$T/m.json" --at 0.5,5,-690 --normal 0,1,0 --sh quadratic >"$T/quad" 2>/dev/null
check "linear and quadratic SH differ" "! cmp -s $T/lin $T/quad"

expect 0 "1 thread" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/t1.json" $FAST --threads 1
expect 0 "2 threads" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/t2.json" $FAST --threads 2
check "the same bytes whatever the thread count" "cmp -s $T/t1.json $T/t2.json"
echo "-- decorators (section 2.1): the static bake's occluders"
# The fixture marks no decorator: auto and off give the bytes of the bake
# before decorators (every triangle opaque).
expect 0 "decorator-source off" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/doff.json" $FAST \
    --threads 2 --decorator-source off
check "no decorator in the level: auto = off, byte for byte" "cmp -s $T/t1.json $T/doff.json"
check "report: no decorator node, the source named" \
    "python3 -c \"import json; d=json.load(open('$T/r.json')); assert d['decorator_nodes']['tree'] == 0 and d['decorator_nodes']['shrub'] == 0 and d['params']['decorator_source'] == 'auto', d['decorator_nodes']\""
TREES=tests/data/levels/aalborg_cut.trees.json
expect 0 "--decorators (the fixture's two tree cards)" -- "$OBSCURA" bake-dynamic "$FIX" \
    -o "$T/dtree.json" --report "$T/dtree.r.json" $FAST --threads 2 --decorators "$TREES"
check "report: 2 tree nodes" "[ \"\$(field $T/dtree.r.json \"['decorator_nodes']['tree']\")\" = 2 ]"
check "the trees semi-transparent: another model" "! cmp -s $T/t1.json $T/dtree.json"
expect 0 "--decorators with decorator-source off" -- "$OBSCURA" bake-dynamic "$FIX" \
    -o "$T/dtoff.json" $FAST --threads 2 --decorators "$TREES" --decorator-source off
check "... the bytes without decorators" "cmp -s $T/t1.json $T/dtoff.json"
# A level whose node is named tree: a canopy 2 above a ground.
cat >"$T/canopy.obj" <<'OBJ'
o ground
v -4 0 -4
v 4 0 -4
v 4 0 4
v -4 0 4
f 1 3 2
f 1 4 3
o tree
v -4 2 -4
v 4 2 -4
v 4 2 4
v -4 2 4
f 5 6 7
f 5 7 8
OBJ
CAN="--rays 256 --max-regions 4 --distance-long 4 -q"
expect 0 "a level with a tree node" -- "$OBSCURA" bake-dynamic "$T/canopy.obj" -o "$T/ctree.json" \
    --report "$T/ctree.r.json" $CAN
check "report: the node named tree is a tree" "[ \"\$(field $T/ctree.r.json \"['decorator_nodes']['tree']\")\" = 1 ]"
expect 0 "... and with decorator-source off" -- "$OBSCURA" bake-dynamic "$T/canopy.obj" \
    -o "$T/copaque.json" $CAN --decorator-source off
check "a tree node: another model than all opaque" "! cmp -s $T/ctree.json $T/copaque.json"
"$OBSCURA" bake-dynamic --eval "$T/ctree.json" --at 0.3,1,0.2 --normal 0,1,0 >"$T/ctree.ao" 2>/dev/null
"$OBSCURA" bake-dynamic --eval "$T/copaque.json" --at 0.3,1,0.2 --normal 0,1,0 >"$T/copaque.ao" 2>/dev/null
check "under the canopy, facing up: brighter through a tree than under an opaque roof" \
    "python3 -c \"import sys; t=float(open('$T/ctree.ao').read()); o=float(open('$T/copaque.ao').read()); print(t, o); sys.exit(not t > o + 0.1)\""
printf '{"decorators": [{"name": "tree", "class": "palm"}]}\n' >"$T/bad_class.json"
expect 3 "a decorators file with an unknown class" -- "$OBSCURA" bake-dynamic "$T/canopy.obj" \
    -o "$T/x.json" $CAN --decorators "$T/bad_class.json"
said "palm"
expect 3 "a missing decorators file" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" \
    --decorators "$T/none.json" -q
echo "-- shards: --shard I/N then --merge"
for n in 1 3 4; do
    i=0; ok_shards=1
    while [ $i -lt $n ]; do
        "$OBSCURA" bake-dynamic "$FIX" --shard $i/$n -o "$T/dpart$n.$i.bin" $FAST --threads 2 2>"$T/err" || ok_shards=0
        i=$((i + 1))
    done
    check "$n shard(s) traced" "[ $ok_shards = 1 ]"
    # given backwards: the merge takes any order; the parts' rays (64) taken
    expect 0 "merge of $n shard(s)" -- "$OBSCURA" bake-dynamic "$FIX" --merge $(ls -r "$T"/dpart$n.*.bin) \
        -o "$T/dmerged$n.json" --max-regions 24 --report "$T/dmerged$n.r.json" -q
    check "merged of $n = unsharded, byte for byte" "cmp -s $T/t1.json $T/dmerged$n.json"
    check "merged of $n: the parts' rays (64) and counts in the report" \
        "python3 -c \"import json; a=json.load(open('$T/dmerged$n.r.json')); b=json.load(open('$T/r.json')); assert a['params']['rays'] == 64 and a['counts']['points_valid'] == b['counts']['points_valid'] and a['counts']['rays'] == b['counts']['rays'], (a['counts'], b['counts'])\""
done
check "parts: 128-byte header, 145 bytes a point, every point once" \
    "python3 -c \"import os,struct,glob; fs=sorted(glob.glob('$T/dpart3.*.bin')); h=[open(f,'rb').read(128) for f in fs]; n=[struct.unpack_from('<Q',x,48)[0] for x in h]; assert all(x[:8]==b'OBSDYNPT' for x in h) and all(os.path.getsize(f)==128+145*k for f,k in zip(fs,n)) and sum(n)==struct.unpack_from('<Q',h[0],32)[0], n\""
expect 3 "a missing shard" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/dpart4.0.bin" "$T/dpart4.1.bin" "$T/dpart4.3.bin" -o "$T/x.json" -q
said "1 of 4 shards missing (2)"
expect 3 "a shard twice" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/dpart3.0.bin" "$T/dpart3.1.bin" "$T/dpart3.1.bin" -o "$T/x.json" -q
said "shard 1/3 given twice"
expect 3 "shards of two splits" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/dpart3.0.bin" "$T/dpart4.1.bin" "$T/dpart3.2.bin" -o "$T/x.json" -q
said "different splits"
head -c 1000 "$T/dpart3.1.bin" >"$T/dcut.bin"
expect 3 "a truncated part" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/dpart3.0.bin" "$T/dcut.bin" "$T/dpart3.2.bin" -o "$T/x.json" -q
said "truncated: 1000 bytes"
"$OBSCURA" bake-dynamic "$FIX" --shard 1/3 -o "$T/drays.bin" --rays 32 --max-regions 24 -q
expect 3 "parts traced with other rays" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/dpart3.0.bin" "$T/drays.bin" "$T/dpart3.2.bin" -o "$T/x.json" -q
said "different rays (64 and 32)"
expect 3 "a merge asking for other rays" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T"/dpart1.0.bin -o "$T/x.json" --rays 8 -q
said "traced with rays 64; this merge asks for 8"
echo '{"regions": [{"min": [0, 0, 0], "max": [1, 1, 1]}]}' >"$T/one.json"
expect 3 "a merge over other regions" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T"/dpart1.0.bin -o "$T/x.json" --regions "$T/one.json" -q
said "give the merge the shards' --regions"
cat >"$T/box.obj" <<'OBJ'
v -2 0 -2
v 2 0 -2
v 2 0 2
v -2 0 2
v -2 2 -2
v 2 2 -2
f 1 3 2
f 1 4 3
f 1 2 6
f 1 6 5
OBJ
expect 0 "a shard of another level" -- "$OBSCURA" bake-dynamic "$T/box.obj" --shard 0/1 -o "$T/dbox.bin" --rays 16 --max-regions 2 -q
expect 3 "a part of another level" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/dbox.bin" -o "$T/x.json" -q
said "traced from another level"
# The decorators are folded into the parts' level fingerprint.
expect 0 "a shard traced with decorators" -- "$OBSCURA" bake-dynamic "$FIX" --shard 0/1 \
    -o "$T/ddec.bin" $FAST --decorators "$TREES"
expect 3 "... merged without them" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/ddec.bin" \
    -o "$T/x.json" --max-regions 24 -q
said "or with other decorators"
expect 3 "... merged with another tree attenuation" -- "$OBSCURA" bake-dynamic "$FIX" \
    --merge "$T/ddec.bin" -o "$T/x.json" --max-regions 24 --decorators "$TREES" \
    --tree-attenuation 0.25 -q
said "or with other decorators"
expect 0 "... merged with them" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/ddec.bin" \
    -o "$T/ddec.json" --max-regions 24 --decorators "$TREES" -q
check "merged with decorators = unsharded, byte for byte" "cmp -s $T/dtree.json $T/ddec.json"
expect 3 "a part without decorators merged with them" -- "$OBSCURA" bake-dynamic "$FIX" \
    --merge "$T/dpart1.0.bin" -o "$T/x.json" --max-regions 24 --decorators "$TREES" -q
said "or with other decorators"
expect 0 "a part of obscura bake" -- "$OBSCURA" bake "$T/box.obj" --shard 0/1 -o "$T/sbox.bin" --rays 4 -q
expect 3 "... is not a bake-dynamic part" -- "$OBSCURA" bake-dynamic "$T/box.obj" --merge "$T/sbox.bin" -o "$T/x.json" -q
said "not a bake-dynamic part"
expect 3 "a model is not a part" -- "$OBSCURA" bake-dynamic "$FIX" --merge "$T/t1.json" -o "$T/x.json" -q
said "no 'OBSDYNPT' magic"
expect 2 "--shard 4/4" -- "$OBSCURA" bake-dynamic "$FIX" --shard 4/4 -o "$T/x.bin"
said "0 <= I < N"
expect 2 "--merge without parts" -- "$OBSCURA" bake-dynamic "$FIX" --merge -o "$T/x.json"
said "needs the part files"
expect 2 "--shard and --merge" -- "$OBSCURA" bake-dynamic "$FIX" --shard 0/2 --merge "$T/dpart1.0.bin" -o "$T/x.json"
said "not both"
check "no part left behind by the refused runs" "[ ! -e $T/x.bin ] && [ ! -e $T/x.json ]"

echo "-- gbuffer --dynamic: a dynamic object in the baked level"
expect 0 "bake the fixture's vertices" -- "$OBSCURA" bake "$FIX" -o "$T/a.glb" --rays 16 -q
# a cube of 3 m inside region 0 of the model (the aalborg cut's first box)
at=$(python3 -c "
import json; r=json.load(open('$T/t1.json'))['regions'][0]
print(','.join(repr(r['min'][a] + (r['max'][a] - r['min'][a]) * f) for a, f in zip(range(3), (0.5, 0.35, 0.5))))")
python3 tests/e2e/lib/glb_dynamic.py "$T/a.glb" "$T/dyn.glb" "$T/dcam.json" dyn_cube "$at" 3
python3 tests/e2e/lib/glb_dynamic.py "$T/a.glb" "$T/dynx.glb" "$T/dcam.json" crate "$at" 3 extras
expect 0 "gbuffer of the level alone" -- "$OBSCURA" gbuffer "$T/a.glb" --camera "$T/dcam.json" -o "$T/g0.exr" -q
expect 0 "gbuffer with the cube, --dynamic-nodes 'dyn_*'" -- "$OBSCURA" gbuffer "$T/dyn.glb" \
    --camera "$T/dcam.json" -o "$T/g1.exr" --dynamic "$T/t1.json" --dynamic-nodes 'dyn_*'
said "pixels of dynamic objects valued from the region model"
expect 0 "the cube's pixels = the model at their P and N (quadratic), the rest unchanged" -- \
    python3 tests/e2e/lib/dyn_gbuffer_check.py "$T/g0.exr" "$T/g1.exr" "$T/t1.json" quadratic
sed 's/^/       /' "$T/out"
expect 1 "... which the linear SH does not give" -- \
    python3 tests/e2e/lib/dyn_gbuffer_check.py "$T/g0.exr" "$T/g1.exr" "$T/t1.json" linear
expect 0 "--dynamic-sh linear" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" \
    -o "$T/g1l.exr" --dynamic "$T/t1.json" --dynamic-nodes 'dyn_*' --dynamic-sh linear -q
expect 0 "--dynamic-sh linear: the model's linear SH" -- \
    python3 tests/e2e/lib/dyn_gbuffer_check.py "$T/g0.exr" "$T/g1l.exr" "$T/t1.json" linear
expect 0 "marked by its extras (\"obscura_dynamic\": true)" -- "$OBSCURA" gbuffer "$T/dynx.glb" \
    --camera "$T/dcam.json" -o "$T/gx.exr" --dynamic "$T/t1.json" -q
expect 0 "... the same check" -- \
    python3 tests/e2e/lib/dyn_gbuffer_check.py "$T/g0.exr" "$T/gx.exr" "$T/t1.json" quadratic
expect 3 "the cube unmarked" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" -o "$T/x.exr" \
    --dynamic "$T/t1.json" -q
said "node 'dyn_cube') primitive 0 has no _AO attribute and is not marked dynamic"
expect 3 "--dynamic on a level without dynamic objects" -- "$OBSCURA" gbuffer "$T/a.glb" \
    --camera "$T/dcam.json" -o "$T/x.exr" --dynamic "$T/t1.json" -q
said "no node is marked dynamic"
expect 3 "a pattern matching no node" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" \
    -o "$T/x.exr" --dynamic "$T/t1.json" --dynamic-nodes 'car*' -q
said "no node's name matches 'car\*'"
expect 3 "a missing model" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" -o "$T/x.exr" \
    --dynamic "$T/none.json" --dynamic-nodes 'dyn_*' -q
said "none.json"
expect 0 "a model of another level" -- "$OBSCURA" bake-dynamic "$T/box.obj" -o "$T/boxm.json" --rays 16 --max-regions 2 -q
expect 3 "... refused" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" -o "$T/x.exr" \
    --dynamic "$T/boxm.json" --dynamic-nodes 'dyn_*' -q
said "baked from another level (4 triangles"
static_node=$(python3 -c "
import json,struct; d=open('$T/a.glb','rb').read(); j=json.loads(d[20:20+struct.unpack_from('<I',d,12)[0]])
print(next(n['name'] for n in j['nodes'] if 'mesh' in n))")
expect 3 "a static node marked dynamic" -- "$OBSCURA" gbuffer "$T/dynx.glb" --camera "$T/dcam.json" \
    -o "$T/x.exr" --dynamic "$T/t1.json" --dynamic-nodes "$static_node" -q
said "the scene's static nodes have"
python3 -c "
import json; d=json.load(open('$T/t1.json')); d.pop('level'); json.dump(d, open('$T/nolevel.json', 'w'))"
expect 0 "a model without its level: a warning" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" \
    -o "$T/gn.exr" --dynamic "$T/nolevel.json" --dynamic-nodes 'dyn_*' -q
said "records no level"
check "... and the same channels" "python3 tests/e2e/lib/dyn_gbuffer_check.py $T/g0.exr $T/gn.exr $T/t1.json quadratic >/dev/null"
expect 3 "a damaged model" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" -o "$T/x.exr" \
    --dynamic "$T/one.json" --dynamic-nodes 'dyn_*' -q
said "not an obscura-dynamic-ao model"
expect 2 "--dynamic-nodes without --dynamic" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" \
    -o "$T/x.exr" --dynamic-nodes 'dyn_*'
said "needs --dynamic MODEL.json"
expect 2 "--dynamic with --deep" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" \
    -o "$T/x.exr" --dynamic "$T/t1.json" --deep
expect 2 "--dynamic-sh cubic" -- "$OBSCURA" gbuffer "$T/dyn.glb" --camera "$T/dcam.json" \
    -o "$T/x.exr" --dynamic "$T/t1.json" --dynamic-sh cubic
check "no G-buffer written by the refused runs" "[ ! -e $T/x.exr ]"

expect 0 "beta 0" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/b0.json" $FAST --beta 0 --report "$T/b0r.json"
check "beta 0: the jumps stay as fitted" \
    "python3 -c \"import json; j=json.load(open('$T/b0r.json'))['boundary_jump']; assert j['mean'][1] == j['mean'][0], j\""
check "beta 0 gives another model" "! cmp -s $T/t1.json $T/b0.json"

# A regions file: two boxes of the built ones, adjacency computed, then
# given.
python3 - "$T/m.json" "$T/two.json" "$T/two_adj.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
lo = [min(r['min'][a] for r in d['regions']) for a in range(3)]
hi = [max(r['max'][a] for r in d['regions']) for a in range(3)]
mid = 0.5 * (lo[0] + hi[0])
boxes = [{"min": lo, "max": [mid, hi[1], hi[2]]}, {"min": [mid, lo[1], lo[2]], "max": hi}]
json.dump({"regions": boxes}, open(sys.argv[2], "w"))
json.dump({"regions": boxes, "adjacency": [[0, 1]]}, open(sys.argv[3], "w"))
PY
expect 0 "--regions: two boxes" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/two_m.json" --regions "$T/two.json" \
    --rays 32 --report "$T/two_r.json" -q
check "--regions: 2 regions, 1 edge" \
    "[ \"\$(field $T/two_r.json \"['counts']['regions']\")\" = 2 ] && [ \"\$(field $T/two_r.json \"['counts']['edges']\")\" = 1 ]"
expect 0 "--regions with adjacency" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/two_a.json" --regions "$T/two_adj.json" --rays 32 -q
check "given adjacency = computed" "cmp -s $T/two_m.json $T/two_a.json"

echo '{"regions": [{"min": [0,0,0], "max": [2,2,2]}, {"min": [1,1,1], "max": [3,3,3]}]}' >"$T/overlap.json"
expect 3 "refuses overlapping boxes" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --regions "$T/overlap.json" -q
said "regions 0 and 1 overlap"
echo '{"regions": [{"min": [0,0,0], "max": [2,0,2]}]}' >"$T/empty.json"
expect 3 "refuses an empty box" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --regions "$T/empty.json" -q
said "region 0 is empty"
echo '{"regions": [{"min": [0,0,0], "max": [1,1,1]}, {"min": [4,0,0], "max": [5,1,1]}], "adjacency": [[0,1]]}' >"$T/apart.json"
expect 3 "refuses adjacency of boxes apart" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --regions "$T/apart.json" -q
said "share no face"
echo '{"regions": [{"min": [0,0,0], "max": [1,1,1]}], "adjacency": [[0,7]]}' >"$T/range.json"
expect 3 "refuses adjacency out of range" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --regions "$T/range.json" -q
said "out of 0..0"
echo '{"regions": ' >"$T/broken.json"
expect 3 "refuses a broken regions file" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --regions "$T/broken.json" -q
said "not JSON"
expect 3 "a missing regions file" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --regions "$T/none.json" -q
expect 3 "a damaged model" -- "$OBSCURA" bake-dynamic --eval "$T/overlap.json" --at 0,0,0
said "not an obscura-dynamic-ao model"
expect 2 "--eval without --at" -- "$OBSCURA" bake-dynamic --eval "$T/m.json"
said "--at X,Y,Z"
expect 2 "--normal of zeros" -- "$OBSCURA" bake-dynamic --eval "$T/m.json" --at 0,0,0 --normal 0,0,0
expect 2 "--sh cubic" -- "$OBSCURA" bake-dynamic --eval "$T/m.json" --at 0,0,0 --sh cubic
expect 2 "no output" -- "$OBSCURA" bake-dynamic "$FIX"
said "no output file"
expect 2 "beta out of range" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --beta -1
said "beta"
expect 2 "an unknown option" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --nope 1
expect 0 "--params" -- "$OBSCURA" bake-dynamic --params
said "absorb-points"
expect 0 "help lists bake-dynamic" -- "$OBSCURA" help
said "bake-dynamic LEVEL"

echo "e2e bake-dynamic: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
