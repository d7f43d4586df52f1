#!/bin/sh
# End-to-end tests of renderer conventions: obscura inspect on the real
# Arnold frame (tests/data, MIT) names Arnold's NDC convention and its
# check; its AO with no flags equals the AO with the correct explicit
# field of view; a sanity warning is printed, and with --strict is an
# error (exit 3) in the CLI, over HTTP (strict=1: 422) and before a
# binary-protocol request is sent; without --strict the frame is computed.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/renderers.sh
#
# Every daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
A=tests/data/arnold_sample2.exr
R=tests/data/room_small.exr
RC=tests/data/room_small.camera.json
. tests/e2e/lib/common.sh

echo "e2e renderers: $OBSCURA"
echo "-- obscura inspect"
"$OBSCURA" inspect "$A" > "$T/inspect.txt" 2>&1
check "inspect $A: exit 0" "[ $? -eq 0 ]"
check "inspect: renderer arnold from its header" "grep -q 'renderer: arnold (from header key arnold/' '$T/inspect.txt'"
check "inspect: worldToNDC in Arnold's convention" "grep -q \"Arnold's -1..1 NDC\" '$T/inspect.txt'"
check "inspect: the lens agrees" "grep -q 'camera check: agrees' '$T/inspect.txt'"
"$OBSCURA" inspect "$R" --json > "$T/inspect.json"
check "inspect --json: blender, planar, world, no warnings" \
    "python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); sys.exit(not (j[\"renderer\"]==\"blender\" and j[\"depth_mode\"]==\"planar\" and j[\"normal_space\"]==\"world\" and j[\"warnings\"]==[]))' '$T/inspect.json'"
"$OBSCURA" inspect /nonexistent.exr > "$T/none.txt" 2>&1
check "inspect of a missing file: exit 3" "[ $? -eq 3 ]"

echo "-- the Arnold frame with no flags"
"$OBSCURA" ao "$A" -o "$T/auto.exr" -q 2>"$T/err"
check "ao $A: exit 0, no warning" "[ $? -eq 0 ] && ! grep -q warning '$T/err'"
# focal 0.972222, aperture 1: fov = 2 atan(1 / (2 * 0.972222)) = 54.432234
"$OBSCURA" ao "$A" --fov-y 54.432234 -o "$T/fov.exr" -q
"$OBSCURA" compare "$T/fov.exr" "$T/auto.exr" --channel-a AO.Y --channel-b AO.Y --mask none --json > "$T/cmp.json"
check "no flags = --fov-y 54.432234 (MAE < 1e-4)" \
    "python3 -c 'import json,sys; sys.exit(not json.load(open(sys.argv[1]))[\"mae\"] < 1e-4)' '$T/cmp.json'"

echo "-- sanity warnings and --strict"
"$OBSCURA" ao "$R" --camera "$RC" --normal-space camera -o "$T/w.exr" -q 2>"$T/err"
rc=$?
check "world normals read as camera: exit 0 with a warning" \
    "[ $rc -eq 0 ] && grep -q 'warning: .*normals look world-space' '$T/err'"
"$OBSCURA" ao "$R" --camera "$RC" --normal-space camera --strict -o "$T/s.exr" -q 2>"$T/err"
rc=$?
check "the same with --strict: exit 3, no output" "[ $rc -eq 3 ] && [ ! -e '$T/s.exr' ]"
"$OBSCURA" ao "$R" --camera "$RC" --strict -o "$T/ok.exr" -q 2>"$T/err"
check "room_small as it is with --strict: exit 0" "[ $? -eq 0 ]"

start d --socket "$T/obscurad.sock" --max-body 8m
WTC=$(python3 -c 'import json,sys; print(",".join(str(v) for r in json.load(open(sys.argv[1]))["world_to_camera"] for v in r))' "$RC")
Q="fov_y=50&near=0.05&far=100&world_to_camera=$WTC&normal_space=camera"
code=$(post "$PORT_d" "$Q&strict=1" "$R" "$T/h.out")
check "HTTP strict=1 on a warned frame: 422 bad_file naming the warning" \
    "[ '$code' = 422 ] && error_is '$T/h.out' bad_file && grep -q 'normals look world-space' '$T/h.out'"
code=$(post "$PORT_d" "$Q" "$R" "$T/h2.out")
check "HTTP without strict: 200 with an X-Obscura-Warning header" \
    "[ '$code' = 200 ] && grep -qi '^X-Obscura-Warning: normals look world-space' '$T/h2.out.h'"
code=$(post "$PORT_d" "fov_y=50&near=0.05&far=100&world_to_camera=$WTC&strict=1" "$R" "$T/h3.out")
check "HTTP strict=1 on room_small as it is: 200" "[ '$code' = 200 ]"
"$OBSCURA" ao "$R" --camera "$RC" --normal-space camera --strict -o "$T/b.exr" -q \
    --server "unix:$T/obscurad.sock" 2>"$T/err"
check "binary protocol client with --strict: exit 3 before sending" "[ $? -eq 3 ]"
"$OBSCURA" ao "$R" --camera "$RC" -o "$T/b2.exr" -q --server "unix:$T/obscurad.sock" 2>"$T/err"
check "binary protocol: the frame as it is: exit 0" "[ $? -eq 0 ]"

echo "-- the camera solved from the position pass"
"$OBSCURA" ao "$R" --camera "$RC" -o "$T/json.exr" -q
"$OBSCURA" ao "$R" -o "$T/solved.exr" 2>"$T/err"
check "CLI, no camera given: solved from the position pass, said so, exit 0" \
    "[ $? -eq 0 ] && grep -q 'solved from the position pass' '$T/err'"
"$OBSCURA" compare "$T/json.exr" "$T/solved.exr" --channel-a AO.Y --channel-b AO.Y --mask none --json > "$T/cmp2.json"
check "solved camera = camera JSON (AO MAE < 1e-4)" \
    "python3 -c 'import json,sys; sys.exit(not json.load(open(sys.argv[1]))[\"mae\"] < 1e-4)' '$T/cmp2.json'"
"$OBSCURA" inspect "$R" > "$T/insp2.txt"
check "inspect: the camera solved from ViewLayer.Position" \
    "grep -q 'camera: solved from the position pass ViewLayer.Position.X' '$T/insp2.txt'"
code=$(post "$PORT_d" "" "$R" "$T/h4.out")
check "HTTP without a camera: solved from the position pass by default, 200" "[ '$code' = 200 ]"
code=$(post "$PORT_d" "solve_camera=0" "$R" "$T/h5.out")
check "HTTP solve_camera=0 without a camera: 422 no_camera" "[ '$code' = 422 ] && error_is '$T/h5.out' no_camera"
for url in "unix:$T/obscurad.sock" "http://127.0.0.1:$PORT_d"; do
    "$OBSCURA" ao "$R" -o "$T/rs.exr" -q --server "$url" 2>"$T/err"
    rc=$?
    "$OBSCURA" compare "$T/solved.exr" "$T/rs.exr" --channel-a AO.Y --channel-b AO.Y --mask none --json > "$T/cmp3.json" 2>/dev/null
    check "no camera, --server $url: solved there, exit 0, the local AO" \
        "[ $rc -eq 0 ] && python3 -c 'import json,sys; sys.exit(not json.load(open(sys.argv[1]))[\"mae\"] < 1e-4)' '$T/cmp3.json'"
done

echo "-- multi-part and multi-view"
B=${OBSCURA_SHARED_DATA:-../shared/data}/openexr-images/Beachball/multipart.0001.exr
if [ -f "$B" ]; then
    "$OBSCURA" inspect "$B" > "$T/bb.txt"
    check "Beachball: the default view right, channels from 2 parts" \
        "grep -q 'view: right, channels gathered from 2 parts' '$T/bb.txt'"
    check "Beachball inspect: every part with its view and channels" \
        "grep -q \"part 5 'depth_right' (view right): Z\" '$T/bb.txt' && [ \$(grep -c '^    part ' '$T/bb.txt') -eq 10 ]"
    "$OBSCURA" inspect "$B" --view left > "$T/bbl.txt"
    check "Beachball --view left: part 1" "grep -q 'part 1 of 10' '$T/bbl.txt'"
    "$OBSCURA" ao "$B" --view left --fov-y 40 -o "$T/bbl.exr" -q
    check "CLI --view left: exit 0" "[ $? -eq 0 ]"
    code=$(post "$PORT_d" "view=left&fov_y=40" "$B" "$T/bb.out")
    check "HTTP view=left: 200" "[ '$code' = 200 ]"
    code=$(post "$PORT_d" "view=middle&fov_y=40" "$B" "$T/bb2.out")
    check "HTTP view=middle: 4xx naming the file's parts" "[ '${code%??}' = 4 ] && grep -q 'depth_right' '$T/bb2.out'"
    "$OBSCURA" ao "$B" --part depth_right --fov-y 40 -o "$T/bbp.exr" -q --server "unix:$T/obscurad.sock"
    check "binary protocol client --part depth_right: exit 0" "[ $? -eq 0 ]"
else
    echo "  skip multi-part checks: $B is absent"
fi
kill -TERM "$PID_d" 2>/dev/null

[ $failed -ne 0 ] && tail -20 "$T/d.log" | sed 's/^/       /'
echo "e2e renderers: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
