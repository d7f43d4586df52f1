#!/bin/sh
# Makes the seeds of tests/fuzz/fuzz_files.c in tests/fuzz/corpus/files
# (each file: one byte naming the parser, then the file) from real files:
# the camera JSONs of tests/data, object-mask selectors of the forms
# README lists against tests/data/small/room_masks.exr, and what the
# CLI writes for a small level (a bake with its own LODs, a dynamic-AO
# model, the parts of a bake and of a bake-dynamic over 2 shards).
# The bake with LODs is also tests/fuzz/lod_scene.glb, the scene whose
# nodes the fuzzed LOD files are matched with.
#
#   OBSCURA=build/obscura sh tests/fuzz/seed_files.sh
set -eu
OBSCURA=${OBSCURA:-build/obscura}
OUT=tests/fuzz/corpus/files
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
mkdir -p "$OUT"
# seed BYTE NAME FILE: the byte (octal escape), then the file
seed() { { printf "$1"; cat "$3"; } >"$OUT/$2"; }

for f in tests/data/*.camera.json tests/data/small/*.camera.json; do
    seed '\000' "camera_$(basename "$f" .camera.json)" "$f"
done
printf '{"world_to_camera":[1,0,0,0,0,1,0,0,0,0,1,-5,0,0,0,1],"fov_y_deg":50,"width":64,"height":48}' >"$T/c"
seed '\000' camera_fov "$T/c"

n=0
for s in 'table' '!table' 'tab*,sofa' 'oak?ha*' '@ViewLayer.CryptoObject:wall_?ack' 'crypto:oak\*Chair' \
         'id:ViewLayer.IndexOB.X=1-3,5' '!id:ViewLayer.IndexOB.X=2' 'matte:ViewLayer.AO.R'; do
    printf '%s' "$s" >"$T/s"
    seed '\001' "mask_$n" "$T/s"
    n=$((n + 1))
done

# a floor and a wall of a few triangles
cat >"$T/box.obj" <<'OBJ'
v -2 0 -2
v 2 0 -2
v 2 0 2
v -2 0 2
v -2 2 -2
v 2 2 -2
v 0 0 0
v 0 1 -2
f 1 7 2
f 2 7 3
f 3 7 4
f 4 7 1
f 1 2 8
f 2 6 8
f 8 6 5
f 1 8 5
OBJ
"$OBSCURA" bake "$T/box.obj" -o "$T/lod.glb" --lods 2 --rays 8 -q
cp "$T/lod.glb" tests/fuzz/lod_scene.glb
seed '\002' lod "$T/lod.glb"
"$OBSCURA" bake-dynamic "$T/box.obj" -o "$T/m.json" --rays 16 --max-regions 3 -q
seed '\003' dyn_model "$T/m.json"
# parts of splits into 1 and 2 shards (the harness reads a part alone:
# a whole split when its count is 1)
for s in 0/1 0/2 1/2; do
    n=$(echo "$s" | tr / _)
    "$OBSCURA" bake "$T/box.obj" --shard $s -o "$T/b$n" --rays 4 -q
    seed '\004' "bake_part_$n" "$T/b$n"
    "$OBSCURA" bake-dynamic "$T/box.obj" --shard $s -o "$T/d$n" --rays 8 --max-regions 2 --grid 3 -q
    seed '\005' "dyn_part_$n" "$T/d$n"
done
# bake-dynamic --regions files (README's layout) and --decorators files
# (tests/data's trees.json; rules naming the seed scene's node)
printf '{"regions": [{"min": [-2,0,-2], "max": [0,2,2]}, {"min": [0,0,-2], "max": [2,2,2]}], "adjacency": [[0,1]]}' >"$T/r"
seed '\006' regions_2 "$T/r"
printf '{"regions": [{"min": [-2,0,-2], "max": [2,2,2]}]}' >"$T/r"
seed '\006' regions_1 "$T/r"
seed '\007' decor_trees tests/data/levels/aalborg_cut.trees.json
printf '{"decorators": [{"name": "defaultobject", "class": "shrub", "density": 2}, {"match": "box*", "class": "tree"}]}' >"$T/d"
seed '\007' decor_rules "$T/d"
# Regressions: the inputs that crashed a parser (or asked for gigabytes),
# rebuilt from the seeds above; each run of the target replays them.
# (regress_bake_part_param and regress_dyn_part_param are libFuzzer's own
# finds, kept as found: a parameter of the header past an int's range.)
python3 - "$OUT" <<'PY'
import struct, sys
out = sys.argv[1]
def put(name, byte, data):
    open(out + "/regress_" + name, "wb").write(bytes([byte]) + data)
# a .glb whose JSON is edited, its lengths kept true
glb = open(out + "/lod", "rb").read()[1:]
magic, ver, total, jlen, jtype = struct.unpack("<5I", glb[:20])
js, rest = glb[20:20 + jlen], glb[20 + jlen:]
def glb_with(old, new):
    assert old in js
    j = js.replace(old, new)
    j += b" " * (-len(j) % 4)
    return struct.pack("<5I", magic, ver, 20 + len(j) + len(rest), len(j), jtype) + j + rest
# node indices that are no integers (a float-to-long conversion out of range)
put("lod_root_string", 2, glb_with(b'"scenes":[{"nodes":[0]}]', b'"scenes":[{"nodes":["x"]}]'))
put("lod_child_1e300", 2, glb_with(b'"children":[1]', b'"children":[1e300]'))
put("lod_id_true", 2, glb_with(b'"ids":[2,3]', b'"ids":[2,true]'))
# a header giving almost 4 GiB for a file of a few hundred bytes
put("lod_length", 2, struct.pack("<5I", magic, ver, 0xfffffff0, jlen, jtype) + js + rest[:64])
# a bake part of shard 0 of 2^31 - 1 over as many samples (one sample):
# the merge sized its tables by that count
part = bytearray(open(out + "/bake_part_0_1", "rb").read()[1:])
struct.pack_into("<I", part, 28, 0x7fffffff)
struct.pack_into("<QQQ", part, 32, 0x7fffffff, 0, 1)
put("bake_part_count", 4, bytes(part[:128 + 9]))
# a model whose region has 1e12 points (a float-to-uint32 conversion out of range)
model = open(out + "/dyn_model", "rb").read()[1:]
i = model.index(b'"points":')
j = i + 9
while model[j:j + 1].isdigit():
    j += 1
put("dyn_model_points", 3, model[:i] + b'"points":1e12' + model[j:])
PY
echo "seeds in $OUT: $(ls "$OUT" | wc -l)"
