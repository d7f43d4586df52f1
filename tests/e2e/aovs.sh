#!/bin/sh
# End-to-end tests of the compositor's outputs: --output aovs (AO.Y,
# AOMultiBounce.R/G/B, BentNormal.X/Y/Z, Samples.Y in one EXR; --append puts them into the
# input's own file) on GL, the CPU device, over HTTP and the binary
# protocol, the same channels everywhere; --multibounce on; --output deep
# (deep input; in-process, over HTTP and the binary protocol): read back with oiiotool, every node's AO (AO.Y / A, the
# channel being premultiplied) in [0, 1], and its flattening (oiiotool
# --flatten, plus the transmittance left, 1 - A) equal to the flat AO
# written beside it.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/aovs.sh
#
# Needs oiiotool (Debian openimageio-tools, tools/deps.sh).
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
R=tests/data/room_small.exr
D=tests/data/deep_small.exr
. tests/e2e/lib/common.sh

echo "e2e aovs: $OBSCURA"
if ! command -v oiiotool >/dev/null 2>&1; then
    echo "  FAIL oiiotool not found: install openimageio-tools (tools/deps.sh)"
    exit 1
fi
# chans FILE [SUBIMAGE]: the channel list oiiotool reads
chans() { oiiotool -a --info -v "$1" 2>&1 | sed -n 's/^ *channel list: //p' | sed -n "${2:-1}p"; }
AOVS="AO.Y, AOMultiBounce.R, AOMultiBounce.G, AOMultiBounce.B, BentNormal.X, BentNormal.Y, BentNormal.Z, Samples.Y"

expect 0 "aovs on GL" -- "$OBSCURA" ao "$R" --output aovs -o "$T/gl.exr"
check "aovs on GL: the AOV table's channels" '[ "$(chans "$T/gl.exr")" = "$AOVS" ]'
expect 0 "aovs on the CPU device" -- "$OBSCURA" ao "$R" --output aovs --backend cpu -o "$T/cpu.exr"
check "aovs on the CPU device: the same channels" '[ "$(chans "$T/cpu.exr")" = "$AOVS" ]'
check "aovs: GL and CPU agree (AO, multi-bounce, bent normal)" \
    'oiiotool "$T/gl.exr" "$T/cpu.exr" --fail 0.01 --failpercent 1 --diff >/dev/null 2>&1'
check "aovs: the multi-bounce AO is at least the AO" \
    'oiiotool "$T/cpu.exr" --ch AOMultiBounce.G "$T/cpu.exr" --ch AO.Y --sub --printstats 2>&1 | grep "Stats Min" | awk "{exit !(\$3 >= -0.001)}"'
expect 0 "aovs of hbao on the CPU device" -- "$OBSCURA" ao "$R" --method hbao --output aovs --backend cpu -o "$T/hbao.exr"
check "aovs of hbao: the bent normal layer too" '[ "$(chans "$T/hbao.exr")" = "$AOVS" ]'
expect 0 "aovs --append" -- "$OBSCURA" ao "$R" --output aovs --append --backend cpu -o "$T/app.exr"
check "aovs --append: the input's channels and the AOVs" \
    'c=$(chans "$T/app.exr"); for n in AO.Y AOMultiBounce.R Samples.Y ViewLayer.Depth.Z ViewLayer.DiffCol.R; do echo "$c" | grep -q "$n" || exit 1; done'
expect 0 "--multibounce on with the albedo" -- "$OBSCURA" ao "$R" --multibounce on --color albedo --output both -o "$T/mb.exr"
check "--multibounce on: AOMultiBounce beside AO.Y and the composite" \
    '[ "$(chans "$T/mb.exr")" = "R, G, B, A, AO.Y, AOMultiBounce.R, AOMultiBounce.G, AOMultiBounce.B" ]'

start_all d
expect 0 "aovs over HTTP" -- "$OBSCURA" ao "$R" --output aovs --server "http://127.0.0.1:$PORT_d" -o "$T/http.exr"
check "aovs over HTTP: the same channels" '[ "$(chans "$T/http.exr")" = "$AOVS" ]'
expect 0 "aovs over the binary protocol" -- "$OBSCURA" ao "$R" --output aovs --server "unix:$SOCK_d" -o "$T/bin.exr"
check "aovs over the binary protocol: the same channels" '[ "$(chans "$T/bin.exr")" = "$AOVS" ]'
check "aovs: HTTP gives GL's pixels" 'oiiotool "$T/http.exr" "$T/gl.exr" --diff >/dev/null 2>&1'
expect 0 "bent normal of gtao over the binary protocol" -- "$OBSCURA" ao "$R" --method gtao --output bent --server "tcp://127.0.0.1:$TCP_d" -o "$T/bent.exr"
check "bent over the binary protocol: BentNormal.X/Y/Z" '[ "$(chans "$T/bent.exr")" = "BentNormal.X, BentNormal.Y, BentNormal.Z" ]'
expect 0 "--output deep over HTTP" -- "$OBSCURA" ao "$D" --output deep --blur off --radius 2 --server "http://127.0.0.1:$PORT_d" -o "$T/deephttp.exr"
expect 0 "--output deep over the binary protocol" -- "$OBSCURA" ao "$D" --output deep --blur off --radius 2 --server "unix:$SOCK_d" -o "$T/deepbin.exr"
check "output=deep of flat input over HTTP: 400" '[ "$(post "$PORT_d" output=deep "$R" "$T/deepflat")" = 400 ]'
kill "$PID_d" 2>/dev/null

# deep: the nodes' AO against the flat AO written beside it (blur off:
# the flat AO is the blended per-node AO itself).  The nodes come from the
# CPU twin of the per-node pass: on the CPU device the flat AO is their
# flattening to rounding; on GL within the twins' tolerance (test_deep).
# flatten FILE OUT: oiiotool's deep flatten of AO.Y, plus 1 - A
flatten() {
    oiiotool "$1" --flatten --ch AO.Y -o "$T/f_ao.exr" &&
        oiiotool "$1" --flatten --ch A -o "$T/f_a.exr" &&
        oiiotool "$T/f_ao.exr" "$T/f_a.exr" --sub --addc 1 -o "$2" &&
        oiiotool "$1" --subimage 1 --ch AO.Y -o "$2.flat.exr"
}
expect 0 "--output deep on the CPU device" -- "$OBSCURA" ao "$D" --output deep --blur off --radius 2 --backend cpu -o "$T/deep.exr"
check "deep: part 0 deep with A, Z, ZBack, AO.Y; part 1 flat AO.Y, AOFront.Y" \
    'oiiotool --info -v "$T/deep.exr" 2>&1 | grep -q "deep float openexr" && [ "$(chans "$T/deep.exr" 2)" = "AO.Y, AOFront.Y" ]'
oiiotool --info --dumpdata:empty=0 "$T/deep.exr" 2>&1 | awk '
    /Pixel/ { n = split($0, s, "/"); for (i = 1; i <= n; i++) {
        a = s[i]; sub(/.*A=/, "", a); sub(/ .*/, "", a);
        o = s[i]; sub(/.*AO\.Y=/, "", o); sub(/ .*/, "", o);
        nodes++; if (a + 0 > 0 && (o / a < -1e-6 || o / a > 1 + 1e-6)) outside++ } }
    END { print nodes " nodes, " outside + 0 " with AO outside [0,1]"; exit !(nodes > 1000 && outside == 0) }' >"$T/range" 2>&1
check "deep: every node's AO in [0, 1] ($(cat "$T/range"))" 'grep -q " 0 with" "$T/range"'
flatten "$T/deep.exr" "$T/fd.exr"
check "deep, CPU device: flattened (over, + 1 - A) equals the flat AO" \
    'oiiotool "$T/fd.exr" "$T/fd.exr.flat.exr" --fail 1e-5 --failpercent 0 --diff >/dev/null 2>&1'
check "deep: some node is occluded" \
    'oiiotool "$T/fd.exr.flat.exr" --printstats 2>&1 | grep "Stats Min" | awk "{exit !(\$3 < 0.9)}"'
expect 0 "--output deep on GL" -- "$OBSCURA" ao "$D" --output deep --blur off --radius 2 -o "$T/deepgl.exr"
flatten "$T/deepgl.exr" "$T/fg.exr"
check "deep, GL: flattened within 1e-3 of GL's flat AO" \
    'oiiotool "$T/fg.exr" "$T/fg.exr.flat.exr" --fail 1e-3 --failpercent 0 --diff >/dev/null 2>&1'
check "deep over HTTP and the binary protocol: the in-process GL file's nodes and flat part" \
    'for f in deephttp deepbin; do for i in 0 1; do oiiotool "$T/$f.exr" --subimage $i "$T/deepgl.exr" --subimage $i --diff >/dev/null 2>&1 || exit 1; done; done'
expect 3 "--output deep of flat input is refused" -- "$OBSCURA" ao "$R" --output deep -o "$T/no.exr"
said "the input is not a deep EXR"
expect 3 "--output deep with another output is refused" -- "$OBSCURA" ao "$D" --output deep,ao -o "$T/no.exr"
said "not with other outputs"
echo "e2e aovs: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
