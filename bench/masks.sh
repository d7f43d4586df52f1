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
#
# With "cycles" (make quality-masks): the same question against Cycles
# itself, when Debian's blender (and sweethome3d-furniture, whose meshes
# the room is made of) are installed, else it says it skipped.
# tools/blender_masks.py renders the room of $S/room.json at 320x240 twice
# (every object, with IndexOB and a Cryptomatte object layer; HIDE, the
# table by default, hidden from rendering); each method's AO of the first
# without a mask, with --occluders '!HIDE' (Cryptomatte, coverage-weighted)
# and with --occluders '!id:ViewLayer.IndexOB.X=N', MSE (obscura compare)
# against the second's AO pass on the pixels both frames show (the
# referee's figures too where ../shared/tools/aometrics.py can run); and
# --receivers HIDE / --receivers id:... leave every pixel the selector
# does not touch exactly 1.  Renders are kept in $BUILD/masks_cycles.
#
#   BUILD=build bench/masks.sh cycles [SPP [HIDE]]   (SPP: Cycles samples, 512)
set -eu
BUILD=${BUILD:-build}
O=$BUILD/obscura
S=${OBSCURA_SHARED_DATA:-../shared/data}/blender
if [ "${1:-}" = cycles ]; then
    SPP=${2:-512} HIDE=${3:-table}
    FURN=/usr/share/sweethome3d/furniture/BlendSwap-CC-0.sh3f
    if ! command -v blender >/dev/null 2>&1 || [ ! -f "$FURN" ] || [ ! -f "$S/room.json" ]; then
        echo "quality-masks: SKIPPED: needs Debian's blender and sweethome3d-furniture" \
            "(tools/deps.sh --quality) and $S/room.json"
        exit 0
    fi
    D=$BUILD/masks_cycles
    mkdir -p "$D"
    blender -b --factory-startup --python tools/blender_masks.py -- "$S/room.json" "$D/room" "$HIDE" \
        --res 320 240 --samples "$SPP" >"$D/blender.log" 2>&1 ||
        { tail -20 "$D/blender.log"; exit 1; }
    grep -E '^(OBJECTS|RENDER_SECONDS|REFERENCE)' "$D/blender.log"
    n=$(sed -n "s/^OBJECTS.* $HIDE=\([0-9]*\).*/\1/p" "$D/blender.log")
    R="$D/room.exr" REF="$D/room_ref.exr" CAM="--camera $D/room.camera.json --radius 0.5"
    mse() { "$O" compare "$1" "$2" --json | sed -n 's/.*"mse": \([^,]*\),.*/\1/p'; }
    echo
    echo "Cycles $SPP spp, distance 0.5, 320x240; MSE against the AO with '$HIDE' hidden, over the pixels both frames show"
    echo "(the two Cycles AO passes differ by MSE $(mse "$REF" "$R" 2>/dev/null || true) there: $HIDE's shadow and both renders' noise)"
    echo
    echo "| method | no mask | --occluders '!$HIDE' | --occluders '!id:ViewLayer.IndexOB.X=$n' |"
    echo "|---|---|---|---|"
    for m in vaopp hemisphere angle hbao gtao; do
        "$O" ao "$R" $CAM --method "$m" -o "$D/$m.exr" 2>/dev/null
        "$O" ao "$R" $CAM --method "$m" --occluders "!$HIDE" -o "$D/${m}_name.exr" 2>/dev/null
        "$O" ao "$R" $CAM --method "$m" --occluders "!id:ViewLayer.IndexOB.X=$n" -o "$D/${m}_id.exr" 2>/dev/null
        printf '| %s | %.5f | %.5f | %.5f |\n' "$m" "$(mse "$REF" "$D/$m.exr")" \
            "$(mse "$REF" "$D/${m}_name.exr")" "$(mse "$REF" "$D/${m}_id.exr")"
    done
    if /usr/bin/python3 -c 'import OpenImageIO, numpy' 2>/dev/null; then
        AOM=${OBSCURA_SHARED_DATA:-../shared/data}/../tools/aometrics.py
        for f in vaopp vaopp_name gtao gtao_name; do
            echo "aometrics.py $f: $(/usr/bin/python3 "$AOM" "$REF" "$D/$f.exr")"
        done
    fi
    # --receivers: every pixel the selector gives weight 0 stays exactly 1
    "$O" ao "$R" $CAM --method gtao --receivers "id:ViewLayer.IndexOB.X=$n" -o "$D/recv_id.exr" 2>/dev/null
    "$O" ao "$R" $CAM --method gtao --receivers "$HIDE" -o "$D/recv_name.exr" 2>/dev/null
    echo "--receivers 'id:ViewLayer.IndexOB.X=$n': max |AO - 1| over the unselected pixels:" \
        "$(tools/unselected_max.sh "$O" "$R" "$D/recv_id.exr" id ViewLayer.IndexOB.X "$n")"
    echo "--receivers '$HIDE': max |AO - 1| over the unselected pixels:" \
        "$(tools/unselected_max.sh "$O" "$R" "$D/recv_name.exr" name ViewLayer.CryptoObject "$HIDE")"
    exit 0
fi
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
