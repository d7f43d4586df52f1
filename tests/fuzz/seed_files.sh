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
echo "seeds in $OUT: $(ls "$OUT" | wc -l)"
