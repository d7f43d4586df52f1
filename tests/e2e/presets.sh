#!/bin/sh
# End-to-end tests of --quality: the preset's frame is the same in
# process, over HTTP (quality=preview) and over the binary protocol, an
# explicit parameter wins over the preset, /v1/params lists the presets,
# and a preset the chain cannot run with another parameter is refused by
# name (400 over HTTP, exit 3 in the CLI).
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/presets.sh
#
# Every daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
R=tests/data/room_small.exr
. tests/e2e/lib/common.sh
W2C=$(tr -d ' \n' < tests/data/room_small.camera.json |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
Q="fov_y=50&near=0.05&far=100&world_to_camera=$W2C"
CAMF="--fov-y 50 --near 0.05 --far 100 --world-to-camera $W2C"

echo "e2e presets: $OBSCURAD"
"$OBSCURA" ao "$R" $CAMF --quality preview --float -o "$T/p.exr" -q
"$OBSCURA" ao "$R" $CAMF --float -o "$T/d.exr" -q
"$OBSCURA" ao "$R" $CAMF --quality preview --ao-resolution full --float -o "$T/pf.exr" -q
# the same pixels (the files' obscura/params say how each was asked for)
check "in process: preview differs from default, and --ao-resolution full wins over it" \
    "! cmp -s '$T/p.exr' '$T/d.exr' && oiiotool -q '$T/pf.exr' '$T/d.exr' --diff --fail 0 >/dev/null 2>&1"

start A --socket "$T/a.sock"
st=$(post "$PORT_A" "$Q&quality=preview&float=1&compression=zip" "$R" "$T/h.exr") # zip: the CLI file's
check "HTTP quality=preview: the in-process bytes ($st)" "[ '$st' = 200 ] && cmp -s '$T/h.exr' '$T/p.exr'"
"$OBSCURA" ao "$R" $CAMF --quality preview --float -o "$T/b.exr" --server "unix:$T/a.sock" -q
mae=$("$OBSCURA" compare "$T/p.exr" "$T/b.exr" --mask none --json | sed -n 's/.*"mae": \([-0-9.e+]*\).*/\1/p')
check "binary protocol --quality preview: the in-process AO (MAE $mae)" \
    "[ -n '$mae' ] && awk 'BEGIN { exit !($mae < 1e-6) }'"
st=$(get "$PORT_A" /v1/params "$T/params.json")
check "/v1/params lists quality and its presets ($st)" \
    "[ '$st' = 200 ] && tr -d ' \\n\\t' < '$T/params.json' | grep -q '\"choices\":\[\"preview\",\"default\",\"high\",\"reference\"\]' && grep -q '\"ao_resolution\"' '$T/params.json'"
st=$(post "$PORT_A" "$Q&quality=preview&bleeding=full" "$R" "$T/e.json")
check "HTTP quality=preview with bleeding: 400 naming both ($st)" \
    "[ '$st' = 400 ] && grep -q 'bleeding' '$T/e.json' && grep -q 'ao_resolution half' '$T/e.json'"
"$OBSCURA" ao "$R" $CAMF --quality preview --output samples -o "$T/s.exr" -q 2>"$T/s.err"
rc=$?
check "CLI --quality preview --output samples: refused, naming it (rc $rc)" \
    "[ $rc -ne 0 ] && grep -q 'sample_count' '$T/s.err'"

echo "e2e presets: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
