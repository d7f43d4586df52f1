#!/bin/sh
# End-to-end tests of the ground-truth commands: `obscura gbuffer` and
# `obscura reference` on meshes written here (flat, and deep with a
# transparent pane: `gbuffer --deep`, `reference --alpha`) and on the
# Blender room of ../shared/data when present, `obscura ao` on the
# G-buffer with no camera flag (the camera comes from the EXR header),
# `obscura compare --json --diff`, and clear errors for bad input.
#
#   OBSCURA=build/obscura tests/e2e/ground.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
. tests/e2e/lib/common.sh
SAID_ERR_ONLY=1
json() { sed -n "s/.*\"$1\": \([-0-9.e+]*\).*/\1/p" "$T/out"; }

echo "e2e ground: $OBSCURA"
# a floor, a wall and a box on the floor; a camera looking at the corner
cat >"$T/corner.obj" <<'OBJ'
v -2 -2 0
v 2 -2 0
v 2 2 0
v -2 2 0
v -2 2 0
v 2 2 0
v 2 2 2
v -2 2 2
v -0.3 0.8 0
v 0.3 0.8 0
v 0.3 0.8 0.5
v -0.3 0.8 0.5
f 1 2 3 4
f 5 6 7 8
f 9 10 11 12
OBJ
cat >"$T/corner.camera.json" <<'CAM'
{"width": 160, "height": 120, "fov_y_deg": 50, "near": 0.05, "far": 100,
 "world_to_camera": [[1, 0, 0, 0], [0, 0.5547002, 0.8320503, -1.6641006],
                     [0, -0.8320503, 0.5547002, -4.4376016], [0, 0, 0, 1]]}
CAM
C="$T/corner.camera.json"

echo "-- gbuffer"
expect 0 "gbuffer corner.obj" -- "$OBSCURA" gbuffer "$T/corner.obj" --camera "$C" -o "$T/gb.exr"
expect 0 "G-buffer has Z, N, Ncam, P, A" -- "$OBSCURA" compare "$T/gb.exr" "$T/gb.exr" \
    --channel-a Ncam.Z --channel-b A --mask none
expect 0 "ao on the G-buffer, camera from its header" -- "$OBSCURA" ao "$T/gb.exr" -o "$T/ao.exr"
expect 0 "gbuffer --width/--height" -- "$OBSCURA" gbuffer "$T/corner.obj" --camera "$C" \
    --width 80 --height 60 -o "$T/gb_half.exr" -q

echo "-- reference"
expect 0 "reference corner.obj" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" \
    -o "$T/ref.exr" --spp 32 --threads 2
expect 0 "reference from the G-buffer's points" -- "$OBSCURA" reference "$T/corner.obj" \
    --gbuffer "$T/gb.exr" -o "$T/ref_gb.exr" --spp 32
expect 0 "reference as PNG" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" -o "$T/ref.png" --spp 4 -q
expect 0 "compare reference and ao --json --diff" -- "$OBSCURA" compare "$T/ref.exr" "$T/ao.exr" \
    --json --diff "$T/diff.exr"
mae=$(json mae); pixels=$(json pixels)
check "compare JSON has mae ($mae) and pixels ($pixels)" "[ -n '$mae' ] && [ '$pixels' -gt 1000 ]"
check "the diff EXR was written" "[ -s '$T/diff.exr' ]"
expect 0 "camera rays and G-buffer points agree" -- "$OBSCURA" compare "$T/ref.exr" "$T/ref_gb.exr" --json
mae=$(json mae)
check "camera rays vs G-buffer points: MAE $mae < 0.05" "awk 'BEGIN { exit !($mae < 0.05) }'"

echo "-- reference --obscurance (the bake's eq 1 per pixel)"
expect 0 "reference --obscurance 0.5,4 --blend 0.25" -- "$OBSCURA" reference "$T/corner.obj" \
    --camera "$C" -o "$T/obs.exr" --obscurance 0.5,4 --blend 0.25 --spp 16 -q
expect 0 "short against long distance" -- "$OBSCURA" compare "$T/obs.exr" "$T/obs.exr" \
    --channel-a AO_SHORT.Y --channel-b AO_LONG.Y --json
bias=$(json bias)
check "the long distance is darker: bias $bias < -0.01" "awk 'BEGIN { exit !($bias < -0.01) }'"
expect 0 "the blend against the short distance" -- "$OBSCURA" compare "$T/obs.exr" "$T/obs.exr" \
    --channel-a AO_SHORT.Y --channel-b AO.Y --json
b2=$(json bias)
check "AO.Y = 0.25 short + 0.75 long: bias $b2 = 0.75 x $bias" \
    "awk 'BEGIN { d = $b2 - 0.75 * $bias; exit !(d < 1e-4 && d > -1e-4) }'"
expect 0 "reference --obscurance as PNG (the blend)" -- "$OBSCURA" reference "$T/corner.obj" \
    --camera "$C" -o "$T/obs.png" --obscurance 2,300 --spp 4 -q
expect 0 "reference --obscurance --near 0.5 (both scales)" -- "$OBSCURA" reference "$T/corner.obj" \
    --camera "$C" -o "$T/obs5.exr" --obscurance 0.5,4 --near 0.5 --spp 16 -q
expect 0 "AO_BOTH against AO_NEAR" -- "$OBSCURA" compare "$T/obs5.exr" "$T/obs5.exr" \
    --channel-a AO_NEAR.Y --channel-b AO_BOTH.Y --json
b3=$(json bias)
check "AO_BOTH = AO_NEAR x AO_LONG is darker: bias $b3 < 0" "awk 'BEGIN { exit !($b3 < 0) }'"
expect 2 "--near without --obscurance" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" \
    -o "$T/x.exr" --near 0.5
said "needs --obscurance"
expect 2 "--near 0" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" \
    -o "$T/x.exr" --obscurance 2,300 --near 0
for bad_list in 2 2,3,4 ,3 2, a,b 0,300 2,-1; do
    expect 2 "--obscurance '$bad_list'" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" \
        -o "$T/x.exr" --obscurance "$bad_list"
done
said "distance_long"
expect 2 "--blend out of range" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" \
    -o "$T/x.exr" --obscurance 2,300 --blend 1.5
said "blend"
expect 2 "--blend without --obscurance" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" \
    -o "$T/x.exr" --blend 0.5
said "needs --obscurance"
expect 2 "--alpha with --obscurance" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" \
    -o "$T/x.exr" --obscurance 2,300 --alpha 0.5
said "opaque"

echo "-- deep: gbuffer --deep, reference --alpha"
# a floor, a wall, a box and a pane in front of it (named objects)
cat >"$T/pane.obj" <<'OBJ'
o floor
v -3 -3 0
v 3 -3 0
v 3 2 0
v -3 2 0
f 1 2 3 4
o wall
v -3 2 0
v 3 2 0
v 3 2 2
v -3 2 2
f 5 6 7 8
o box
v -0.4 0.25 0
v 0.3 0.25 0
v 0.3 0.8 0
v -0.4 0.8 0
v -0.4 0.25 0.6
v 0.3 0.25 0.6
v 0.3 0.8 0.6
v -0.4 0.8 0.6
f 9 10 14 13
f 10 11 15 14
f 11 12 16 15
f 12 9 13 16
f 13 14 15 16
o pane
v -1 0 0
v 1 0 0
v 1 0 0.9
v -1 0 0.9
f 17 18 19 20
OBJ
expect 0 "gbuffer --deep --alpha pane=0.5" -- "$OBSCURA" gbuffer "$T/pane.obj" --camera "$C" \
    --deep --alpha pane=0.5 -o "$T/deep.exr"
said "deep, [0-9]* samples"
expect 0 "ao on the deep G-buffer (multi-layer)" -- "$OBSCURA" ao "$T/deep.exr" -o "$T/multi.exr" -q
expect 0 "ao on the deep G-buffer (single-layer)" -- "$OBSCURA" ao "$T/deep.exr" \
    --deep-mode single -o "$T/single.exr" -q
expect 0 "reference --alpha pane=0.5" -- "$OBSCURA" reference "$T/pane.obj" --camera "$C" \
    --alpha pane=0.5 -o "$T/ref_alpha.exr" --spp 32 --threads 2 -q
expect 0 "compare multi-layer" -- "$OBSCURA" compare "$T/ref_alpha.exr" "$T/multi.exr" --json
mse_multi=$(json mse)
expect 0 "compare single-layer" -- "$OBSCURA" compare "$T/ref_alpha.exr" "$T/single.exr" --json
mse_single=$(json mse)
check "multi-layer MSE $mse_multi < single-layer MSE $mse_single" \
    "awk 'BEGIN { exit !($mse_multi < $mse_single) }'"
expect 2 "--alpha needs --deep" -- "$OBSCURA" gbuffer "$T/pane.obj" --camera "$C" --alpha 0.5 -o "$T/x.exr"
expect 2 "--alpha out of range" -- "$OBSCURA" gbuffer "$T/pane.obj" --camera "$C" --deep \
    --alpha pane=1.5 -o "$T/x.exr"
said "expected A or NAME=A"
expect 2 "--alpha without a number" -- "$OBSCURA" reference "$T/pane.obj" --camera "$C" \
    --alpha pane= -o "$T/x.exr"
expect 3 "--alpha naming no mesh" -- "$OBSCURA" gbuffer "$T/pane.obj" --camera "$C" --deep \
    --alpha sofa=0.5 -o "$T/x.exr"
said "no mesh is named 'sofa'"

echo "-- bad input"
expect 3 "missing scene" -- "$OBSCURA" gbuffer "$T/none.obj" --camera "$C" -o "$T/x.exr"
said "none.obj: cannot open"
printf 'ply\nnot a mesh at all\n' >"$T/junk.ply"
expect 3 "unreadable mesh" -- "$OBSCURA" reference "$T/junk.ply" --camera "$C" -o "$T/x.exr"
said "junk.ply"
printf 'v 0 0 0\nv 1 0 0\nl 1 2\n' >"$T/lines.obj"
expect 3 "empty scene" -- "$OBSCURA" gbuffer "$T/lines.obj" --camera "$C" -o "$T/x.exr"
said "no triangles"
# hostile but loadable: finite coordinates of 3e38 (an empty image, exit 0,
# before), every triangle degenerate (the same)
expect 3 "coordinates beyond the bound" -- "$OBSCURA" gbuffer tests/data/levels/bad/coords_3e38.obj \
    --camera "$C" -o "$T/x.exr"
said "vertex 0 (mesh 'defaultobject', node 'defaultobject') at (-3e+38, -3e+38, 0): a coordinate beyond +-1e9"
expect 3 "every triangle degenerate" -- "$OBSCURA" reference tests/data/levels/bad/degenerate.obj \
    --camera "$C" -o "$T/x.exr"
said "all 2 triangles are degenerate"
# a camera 1e30 away: gbuffer drew an empty image, reference aborted in Embree
sed 's/-4.4376016/-4.4376016e30/' "$C" >"$T/far.camera.json"
expect 3 "gbuffer: a camera beyond the bound" -- "$OBSCURA" gbuffer "$T/corner.obj" \
    --camera "$T/far.camera.json" -o "$T/x.exr"
said "the camera at (0, -3.69"
expect 3 "reference: a camera beyond the bound" -- "$OBSCURA" reference "$T/corner.obj" \
    --camera "$T/far.camera.json" -o "$T/x.exr" --spp 4
said "a coordinate beyond +-1e9"
printf '{"fov_y_deg": 500}' >"$T/bad.json"
expect 3 "bad camera" -- "$OBSCURA" gbuffer "$T/corner.obj" --camera "$T/bad.json" -o "$T/x.exr"
said "fov_y_deg"
expect 3 "missing camera file" -- "$OBSCURA" reference "$T/corner.obj" --camera "$T/nocam.json" -o "$T/x.exr"
said "nocam.json"
expect 2 "no camera" -- "$OBSCURA" gbuffer "$T/corner.obj" -o "$T/x.exr"
expect 2 "gbuffer writes EXR only" -- "$OBSCURA" gbuffer "$T/corner.obj" --camera "$C" -o "$T/x.png"
expect 2 "bad --spp" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" -o "$T/x.exr" --spp 0
expect 2 "bad --distance" -- "$OBSCURA" reference "$T/corner.obj" --camera "$C" -o "$T/x.exr" --distance -1
expect 3 "G-buffer without positions" -- "$OBSCURA" reference "$T/corner.obj" --gbuffer "$T/ao.exr" \
    --camera "$C" -o "$T/x.exr"
said "no P.X channels"

B="$SHARED/blender"
if [ -f "$B/room.obj" ]; then
    echo "-- Blender room (shared data)"
    expect 0 "gbuffer room.obj" -- "$OBSCURA" gbuffer "$B/room.obj" --camera "$B/room.camera.json" -o "$T/room_gb.exr"
    expect 0 "ao on the rasterised room" -- "$OBSCURA" ao "$T/room_gb.exr" -o "$T/room_ao.exr"
    expect 0 "compare with Cycles AO" -- "$OBSCURA" compare "$B/room.exr" "$T/room_ao.exr" \
        --channel-a ViewLayer.AO.R --json
    corr=$(json corr)
    check "rasterised room vs Cycles AO: corr $corr > 0.6" "awk 'BEGIN { exit !($corr > 0.6) }'"
fi

echo "e2e ground: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
