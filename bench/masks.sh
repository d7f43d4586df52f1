#!/bin/sh
# The occluders mask against a ray-traced hidden-object reference: the
# Blender room of $OBSCURA_SHARED_DATA/blender (default ../shared/data)
# rasterised with object IDs (obscura gbuffer --ids: 1 + the mesh index),
# the Embree reference AO at the G-buffer's points with every mesh and
# with the table (meshes Table*) not occluding (obscura reference --alpha
# 'Table*=0': rays pass through it), and each method's AO without a mask
# and with --occluders '!id:id=13-29' (everything but the table's
# meshes).  Prints the MSE of each against both references (obscura
# compare, geometry pixels): the mask should bring every method closer to
# the hidden-table reference.  The issue asked for a Cycles render with a
# Cryptomatte layer; the Embree reference with the table transparent to
# rays is the same question (Arnold's trace_set) without Blender.  Draws
# docs/masks.png (build/quality_strip): the two references and gtao
# without a mask; gtao with the mask, with --receivers on the table only,
# and with --self-only.
#
#   BUILD=build bench/masks.sh [SPP]     (SPP: reference samples, 256)
set -eu
BUILD=${BUILD:-build}
O=$BUILD/obscura
S=${OBSCURA_SHARED_DATA:-../shared/data}/blender
SPP=${1:-256}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
SZ="--width 320 --height 240"
"$O" gbuffer "$S/room.obj" --camera "$S/room.camera.json" $SZ --ids -o "$T/g.exr" 2>"$T/ids.txt"
ids=$(sed -n "s/.*id \([0-9]*\): mesh 'Table.*/\1/p" "$T/ids.txt" | sort -n | sed -n '1p;$p' | paste -sd-)
"$O" reference "$S/room.obj" --camera "$S/room.camera.json" $SZ --gbuffer "$T/g.exr" --distance 0.5 \
    --spp "$SPP" -o "$T/full.exr" 2>/dev/null
"$O" reference "$S/room.obj" --camera "$S/room.camera.json" $SZ --gbuffer "$T/g.exr" --distance 0.5 \
    --spp "$SPP" --alpha 'Table*=0' -o "$T/hidden.exr" 2>/dev/null
mse() { "$O" compare "$1" "$2" --json | sed -n 's/.*"mse": \([^,]*\),.*/\1/p'; }
echo "table meshes: id $ids; references at $SPP spp, distance 0.5, 320x240"
echo "full vs hidden reference: MSE $(mse "$T/full.exr" "$T/hidden.exr")"
echo
echo "| method | vs hidden, no mask | vs hidden, --occluders '!id:id=$ids' | vs full, no mask | vs full, mask |"
echo "|---|---|---|---|---|"
for m in vaopp hemisphere angle hbao gtao; do
    "$O" ao "$T/g.exr" --method "$m" --radius 0.5 -o "$T/a.exr" 2>/dev/null
    "$O" ao "$T/g.exr" --method "$m" --radius 0.5 --occluders "!id:id=$ids" -o "$T/m.exr" 2>/dev/null
    printf '| %s | %.5f | %.5f | %.5f | %.5f |\n' "$m" "$(mse "$T/hidden.exr" "$T/a.exr")" \
        "$(mse "$T/hidden.exr" "$T/m.exr")" "$(mse "$T/full.exr" "$T/a.exr")" "$(mse "$T/full.exr" "$T/m.exr")"
    [ "$m" = gtao ] && cp "$T/a.exr" "$T/gtao.exr" && cp "$T/m.exr" "$T/gtao_m.exr"
done
"$O" ao "$T/g.exr" --method gtao --radius 0.5 --receivers "id:id=$ids" -o "$T/gtao_r.exr" 2>/dev/null
"$O" ao "$T/g.exr" --method gtao --radius 0.5 --self-only on --occluders 'id:id=1-999' -o "$T/gtao_s.exr" 2>/dev/null
[ -x "$BUILD/quality_strip" ] || make -s "$BUILD/quality_strip" BUILD="$BUILD"
"$BUILD/quality_strip" docs/masks.png --scale 1 --cols 3 --sky "$T/g.exr" Z \
    --grey "$T/full.exr" AO.Y --grey "$T/hidden.exr" AO.Y --grey "$T/gtao.exr" AO.Y \
    --grey "$T/gtao_m.exr" AO.Y --grey "$T/gtao_r.exr" AO.Y --grey "$T/gtao_s.exr" AO.Y
echo
echo "docs/masks.png: Embree AO (every mesh; the table transparent to rays); gtao without a mask;"
echo "gtao with --occluders '!id:id=$ids'; with --receivers 'id:id=$ids'; with --self-only on"
