#!/bin/sh
# End-to-end tests of what an output says about itself, read back with
# OpenImageIO (oiiotool) as a pipeline would: the obscura/... provenance
# keys in EXR attributes and PNG text chunks, beside the input's own
# attributes (history, chromaticities); the PNGs' transfer tags, checked
# by what oiiotool's default reading makes of them (the AO PNG converted
# from the colour space oiiotool reads in it to linear equals the EXR's
# AO.Y within 8-bit rounding); the composite PNG tagged sRGB.  In process
# and over HTTP.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/provenance.sh
#
# Needs oiiotool (openimageio-tools, tools/deps.sh) and python3 (the PNG
# chunk list: oiiotool reads an untagged PNG as sRGB too).
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
CAMJ="$DATA/room_small.camera.json"
. tests/e2e/lib/common.sh

echo "e2e provenance: $OBSCURA"
if ! command -v oiiotool >/dev/null 2>&1; then
    echo "  FAIL oiiotool not found: install openimageio-tools (tools/deps.sh)"
    exit 1
fi

VERSION=$("$OBSCURA" --version 2>&1 | sed -n 's/^obscura \([0-9][0-9.]*\).*/\1/p' | head -1)
# attr FILE NAME: the value oiiotool reads for that attribute, unquoted
attr() { oiiotool --info -v "$1" 2>/dev/null | sed -n "s|^ *$2: \"\{0,1\}\(.*\)|\1|p" | sed 's|"$||' | head -1; }
# chunks FILE: the PNG's chunk names, one a line
chunks() {
    python3 -c '
import struct, sys
d = open(sys.argv[1], "rb").read(); i = 8
while i + 8 <= len(d):
    n, t = struct.unpack(">I4s", d[i:i + 8]); print(t.decode("latin-1")); i += 12 + n
' "$1" 2>/dev/null
}
# reads_as FILE.png PNGCHANNELS FILE.exr CHANNELS: the PNG's channels as
# oiiotool reads them by default, converted from the colour space it finds
# to linear, equal the EXR's within 8-bit rounding: half an 8-bit step (0.00196) times
# the slope of the sRGB decoding, 2 at most over [0, 1] values near 1
# (a misread transfer is off by up to 0.29)
reads_as() {
    oiiotool -q --fail 0.0045 --hardfail 0.0045 --warn 0.0045 "$3" --ch "$4" "$1" --ch "$2" \
        --tocolorspace linear --diff >/dev/null 2>&1
}

echo "-- EXR: provenance beside the input's attributes"
oiiotool "$R" --attrib:type=float[8] chromaticities "0.708,0.292,0.170,0.797,0.131,0.046,0.3127,0.3290" \
    -o "$T/in.exr" 2>/dev/null
SOFTWARE=$(attr "$T/in.exr" Software)
"$OBSCURA" ao "$T/in.exr" --camera "$CAMJ" --output both --method hbao --hbao-steps 8 -q -o "$T/ao.exr"
check "obscura ao (EXR): obscura/version is $VERSION" '[ -n "$VERSION" ] && [ "$(attr "$T/ao.exr" obscura/version)" = "$VERSION" ]'
check "the input's Software and history kept beside it" \
    '[ -n "$SOFTWARE" ] && [ "$(attr "$T/ao.exr" Software)" = "$SOFTWARE" ] && [ -n "$(attr "$T/ao.exr" Exif:ImageHistory)" ]'
check "the input's chromaticities carried over" \
    '[ "$(attr "$T/ao.exr" chromaticities)" = "0.708, 0.292, 0.17, 0.797, 0.131, 0.046, 0.3127, 0.329" ]'
# method and params come from the caller (the CLI's and the daemon's call
# sites pass obs_provenance); the input's path and the camera's source are
# left out, so that a frame's bytes do not depend on its transport
check "obscura/method hbao" '[ "$(attr "$T/ao.exr" obscura/method)" = hbao ]'
check "obscura/params: the non-default parameters" \
    'attr "$T/ao.exr" obscura/params | grep -q "^method=hbao.* hbao_steps=8"'
check "no obscura/input nor obscura/camera_source (transport-independent bytes)" \
    '[ -z "$(attr "$T/ao.exr" obscura/input)" ] && [ -z "$(attr "$T/ao.exr" obscura/camera_source)" ]'

echo "-- PNG: provenance text, transfer tags read right by oiiotool"
"$OBSCURA" ao "$R" --camera "$CAMJ" --float -q -o "$T/ref.exr" --output both
"$OBSCURA" ao "$R" --camera "$CAMJ" --output both -q -o "$T/p.png"
check "AO PNG: obscura/version text chunk" '[ "$(attr "$T/p.ao.png" obscura/version)" = "$VERSION" ]'
check "composite PNG: obscura/version text chunk" '[ "$(attr "$T/p.composite.png" obscura/version)" = "$VERSION" ]'
check "AO PNG: a transfer tag (sRGB, or gAMA and cICP for linear)" \
    'chunks "$T/p.ao.png" | grep -qx sRGB || { chunks "$T/p.ao.png" | grep -qx gAMA && chunks "$T/p.ao.png" | grep -qx cICP; }'
check "AO PNG read by oiiotool's default (oiio:ColorSpace $(attr "$T/p.ao.png" oiio:ColorSpace)) equals the AO" \
    'reads_as "$T/p.ao.png" Y "$T/ref.exr" AO.Y'
"$OBSCURA" ao "$R" --camera "$CAMJ" --png-transfer linear -q -o "$T/lin.png"
check "--png-transfer linear: gAMA and cICP, read as linear, equals the AO" \
    'chunks "$T/lin.png" | grep -qx gAMA && chunks "$T/lin.png" | grep -qx cICP && [ "$(attr "$T/lin.png" oiio:ColorSpace)" = linear ] && reads_as "$T/lin.png" Y "$T/ref.exr" AO.Y'
check "AO PNG by default: the sRGB chunk (--png-transfer srgb)" 'chunks "$T/p.ao.png" | grep -qx sRGB'
check "composite PNG: sRGB chunk, read as sRGB" \
    'chunks "$T/p.composite.png" | grep -qx sRGB && [ "$(attr "$T/p.composite.png" oiio:ColorSpace)" = sRGB ]'
check "composite PNG read by oiiotool's default equals the composite" \
    'reads_as "$T/p.composite.png" R,G,B "$T/ref.exr" R,G,B'

echo "-- over HTTP"
start d
code=$(post "$PORT_d" "fov_y=50&format=png" "$R" "$T/h.png")
check "HTTP PNG: $code, obscura/version" '[ "$code" = 200 ] && [ "$(attr "$T/h.png" obscura/version)" = "$VERSION" ]'
check "HTTP AO PNG tagged" 'chunks "$T/h.png" | grep -qx sRGB || chunks "$T/h.png" | grep -qx gAMA'
code=$(post "$PORT_d" "fov_y=50" "$R" "$T/h.exr")
check "HTTP EXR: $code, obscura/version beside the input's attributes" \
    '[ "$code" = 200 ] && [ "$(attr "$T/h.exr" obscura/version)" = "$VERSION" ] && [ "$(attr "$T/h.exr" Camera)" = Cam ]'
"$OBSCURA" ao "$R" --camera "$CAMJ" -q --server "http://127.0.0.1:$PORT_d" -o "$T/r.exr"
check "obscura ao --server: obscura/version" '[ "$(attr "$T/r.exr" obscura/version)" = "$VERSION" ]'
kill "$PID_d" 2>/dev/null
wait "$PID_d" 2>/dev/null

[ $failed -ne 0 ] && tail -20 "$T/d.log" | sed 's/^/       /'
echo "e2e provenance: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
