#!/bin/sh
# End-to-end tests of the EXR output a compositor lines up: a cropped
# input's data and display windows kept, and its AO equal to the uncropped
# frame's over the crop; header attributes carried (camera, renderer
# keys); --layer NAME; --append (every input channel unchanged, read back
# with OpenImageIO, plus the AO layer); deep input with --append refused;
# layer= and append=1 over HTTP and the binary protocol.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/output.sh
#
# Needs oiiotool (Debian openimageio-tools, tools/deps.sh).  The daemon it
# starts is killed on exit.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
CAMJ="$DATA/room_small.camera.json"
. tests/e2e/lib/common.sh

echo "e2e output: $OBSCURA"
if ! command -v oiiotool >/dev/null 2>&1; then
    echo "  FAIL oiiotool not found: install openimageio-tools (tools/deps.sh)"
    exit 1
fi

# info FILE: oiiotool's verbose header listing
info() { oiiotool --info -v "$1" 2>&1; }
# windows FILE: the size, data origin and display window lines
windows() { info "$1" | sed -n 's/^[^:]*: *\([0-9]* x *[0-9]*\),.*/size \1/p; s/^ *\(pixel data origin:.*\)/\1/p; s/^ *\(full\/display .*\)/\1/p'; }
# channels FILE: the channel names, one a line
channels() { info "$1" | sed -n 's/^ *channel list: //p' | tr ',' '\n' | sed 's/^ *//; s/ (.*)$//'; }
# same_region A B WxH+X+Y: the pixels of A and B over that region are equal
same_region() { oiiotool -q "$1" --crop "$3" "$2" --crop "$3" --diff >/dev/null 2>&1; }

echo "-- a cropped input (data window inside a larger display window)"
# The 3x3 rotation pattern is counted from the display window's corner;
# the culling pre-pass's 8x8 tiles from the data window's, so the crops
# here start at multiples of 8: 48, and 16 (not a multiple of 3).
oiiotool "$R" --crop 224x144+48+48 -o "$T/crop.exr"
check "the cropped copy has data window 224x144 at (48,48) in 320x240" \
    "windows '$T/crop.exr' | grep -q 'pixel data origin: x=48, y=48' && windows '$T/crop.exr' | grep -q 'display size: 320 x 240'"
for how in --cpu ""; do
    "$OBSCURA" ao "$R" --camera "$CAMJ" $how --radius 0.05 --float -q -o "$T/full.exr"
    "$OBSCURA" ao "$T/crop.exr" --camera "$CAMJ" $how --radius 0.05 --float -q -o "$T/cropao.exr"
    check "${how:-gl}: the AO's data and display windows are the input's" \
        "[ \"\$(windows '$T/crop.exr')\" = \"\$(windows '$T/cropao.exr')\" ] && [ -n \"\$(windows '$T/cropao.exr')\" ]"
    # 16 px in from the crop's edges the sample disks (radius 0.05) lie
    # inside the crop: there the AO is the uncropped frame's, exactly.
    check "${how:-gl}: AO over the crop (16 px in) = the uncropped run's" \
        "same_region '$T/full.exr' '$T/cropao.exr' 192x112+64+64"
done
oiiotool "$R" --crop 224x144+16+16 -o "$T/crop16.exr"
for how in --cpu ""; do
    "$OBSCURA" ao "$R" --camera "$CAMJ" $how --radius 0.05 --float -q -o "$T/full16.exr"
    "$OBSCURA" ao "$T/crop16.exr" --camera "$CAMJ" $how --radius 0.05 --float -q -o "$T/crop16ao.exr"
    # The disk map folds the data window's offset into its coefficients,
    # so at another offset a sample within float rounding of a pixel
    # border may land on its other side, and the blur spreads it to its
    # taps: room_small has one such pixel on the CPU (15 after the blur,
    # 0.07 %), none on GL. With the 3x3 tile out of step (counted from the
    # data window's corner, as before) most pixels differ.
    check "${how:-gl}: a crop at (16,16): AO over it (16 px in) = the uncropped run's (but 0.5 % of pixels)" \
        "oiiotool -q '$T/full16.exr' --crop 192x112+32+32 '$T/crop16ao.exr' --crop 192x112+32+32 --fail 1e-6 --failpercent 0.5 --diff >/dev/null 2>&1"
done
check "the negative check can fail: AO shifted by one pixel differs" \
    "! oiiotool -q '$T/full.exr' --crop 192x112+64+64 '$T/cropao.exr' --crop 192x112+65+64 --origin +64+64 --diff >/dev/null 2>&1"

echo "-- header attributes carried"
W2C="0.791285,-0.128984,-0.597688,0,0.611448,0.166921,0.773479,0,5.96047e-08,0.977497,-0.210949,0,-0.100709,-0.792241,4.38773,1"
NDC="0.337499,-0.16054,-0.598286,-0.597688,0.87846,0.207758,0.774253,0.773479,-0.105474,-1.1536,-0.21116,-0.210949,2.11288,3.04335,4.29207,4.38773"
oiiotool "$T/crop.exr" --attrib:type=matrix worldToCamera "$W2C" --attrib:type=matrix worldToNDC "$NDC" \
    --attrib "arnold/version" "test-7.1" --attrib:type=float "rs/camera/fov" 50.5 -o "$T/withcam.exr"
"$OBSCURA" ao "$T/withcam.exr" --radius 0.05 -q -o "$T/camao.exr"
rc=$?
for a in worldToCamera worldToNDC arnold/version rs/camera/fov BlenderMultiChannel cycles.ViewLayer.samples Camera; do
    in=$(info "$T/withcam.exr" | grep "^ *$a:")
    out=$(info "$T/camao.exr" | grep "^ *$a:")
    check "exit $rc; $a carried unchanged (${out# *})" "[ $rc -eq 0 ] && [ -n \"\$in\" ] && [ \"\$in\" = \"\$out\" ]"
done
check "the output's channels are only the AO (AO.Y)" "[ \"\$(channels '$T/camao.exr')\" = AO.Y ]"

echo "-- --layer"
"$OBSCURA" ao "$T/crop.exr" --camera "$CAMJ" --cpu -q --layer occlusion --output both -o "$T/layer.exr"
check "--layer occlusion --output both: occlusion.A,B,G,R,Y" \
    "[ \"\$(channels '$T/layer.exr' | sort | tr '\n' ' ')\" = 'occlusion.A occlusion.B occlusion.G occlusion.R occlusion.Y ' ]"
"$OBSCURA" ao "$T/crop.exr" --camera "$CAMJ" --cpu -q --layer ".bad" -o "$T/x.exr" 2>"$T/err"
rc=$?
check "--layer .bad: usage error (exit $rc) naming the layer" "[ $rc -eq 2 ] && grep -q 'layer name' '$T/err'"
"$OBSCURA" ao "$T/crop.exr" --camera "$CAMJ" --cpu -q --layer occ -o "$T/x.png" 2>"$T/err"
rc=$?
check "--layer with a PNG output: usage error (exit $rc)" "[ $rc -eq 2 ] && grep -q 'PNG' '$T/err'"

echo "-- --append"
"$OBSCURA" ao "$T/crop.exr" --camera "$CAMJ" --cpu --radius 0.05 -q --append --layer occ -o "$T/app.exr"
rc=$?
n_in=$(channels "$T/crop.exr" | wc -l)
check "exit $rc; OpenImageIO reads it: the input's $n_in channels plus occ.Y" \
    "[ $rc -eq 0 ] && [ \"\$(channels '$T/app.exr' | sort)\" = \"\$( (channels '$T/crop.exr'; echo occ.Y) | sort)\" ]"
allsame=1
for c in $(channels "$T/crop.exr"); do
    oiiotool -q "$T/crop.exr" --ch "$c" "$T/app.exr" --ch "$c" --diff >/dev/null 2>&1 || { allsame=0; echo "       differs: $c"; }
done
check "every input channel's pixels unchanged (oiiotool --diff, $n_in channels)" "[ $allsame -eq 1 ]"
"$OBSCURA" ao "$T/crop.exr" --camera "$CAMJ" --cpu --radius 0.05 -q -o "$T/plain.exr"
check "the AO layer = the AO written on its own, exactly" \
    "oiiotool -q '$T/app.exr' --ch 'AO.Y=occ.Y' '$T/plain.exr' --diff >/dev/null 2>&1"
check "the appended file keeps the windows and the header" \
    "[ \"\$(windows '$T/crop.exr')\" = \"\$(windows '$T/app.exr')\" ] && info '$T/app.exr' | grep -q 'cycles.ViewLayer.samples: \"64\"'"
"$OBSCURA" ao "$T/app.exr" --camera "$CAMJ" --cpu -q --append --layer occ -o "$T/app2.exr" 2>"$T/err"
rc=$?
check "--append onto a file that has occ.Y: refused (exit $rc), naming the channel" \
    "[ $rc -ne 0 ] && grep -q \"already has a channel 'occ.Y'\" '$T/err' && [ ! -e '$T/app2.exr' ]"
"$OBSCURA" ao "$DATA/deep_small.exr" --cpu -q --append -o "$T/deep.exr" 2>"$T/err"
rc=$?
check "deep input with --append: refused (exit $rc): $(head -c 100 "$T/err")" \
    "[ $rc -ne 0 ] && grep -q 'deep' '$T/err' && [ ! -e '$T/deep.exr' ]"
cp "$T/crop.exr" "$T/inplace.exr"
"$OBSCURA" ao "$T/inplace.exr" --camera "$CAMJ" --cpu --radius 0.05 -q --append --layer occ -o "$T/inplace.exr"
rc=$?
check "--append onto the input itself (-o the same file): exit $rc, the same file as to another path" \
    "[ $rc -eq 0 ] && cmp -s '$T/inplace.exr' '$T/app.exr'"
# a multi-part input: every part kept, the AO in the part read
oiiotool "$T/crop.exr" --ch ViewLayer.Combined.R,ViewLayer.Combined.G,ViewLayer.Combined.B "$T/crop.exr" \
    --ch ViewLayer.Depth.Z,ViewLayer.Normal.X,ViewLayer.Normal.Y,ViewLayer.Normal.Z --siappend -o "$T/multi.exr" 2>/dev/null
"$OBSCURA" ao "$T/multi.exr" --camera "$CAMJ" --cpu -q --append -o "$T/multiapp.exr"
rc=$?
check "multi-part input: exit $rc, both parts, the AO added to the second (the one read)" \
    "[ $rc -eq 0 ] && oiiotool --info -a '$T/multiapp.exr' 2>&1 | grep -q 'subimage  0: *224 x  144, 3 channel' &&
     oiiotool --info -a '$T/multiapp.exr' 2>&1 | grep -q 'subimage  1: *224 x  144, 5 channel'"

echo "-- over HTTP and the binary protocol"
start_all d
TP=$TCP_d
Q="fov_y=50&near=0.05&far=100&world_to_camera=$(echo "$W2C" | sed 's/,/%2C/g')&radius=0.05"
code=$(post "$PORT_d" "append=1&layer=occ&$Q" "$T/crop.exr" "$T/happ.exr")
check "POST append=1&layer=occ: $code, the input's channels plus occ.Y" \
    "[ '$code' = 200 ] && [ \"\$(channels '$T/happ.exr' | sort)\" = \"\$( (channels '$T/crop.exr'; echo occ.Y) | sort)\" ]"
check "HTTP append: the windows kept" "[ \"\$(windows '$T/crop.exr')\" = \"\$(windows '$T/happ.exr')\" ]"
code=$(post "$PORT_d" "$Q" "$T/crop.exr" "$T/hao.exr")
check "POST plain: $code, the windows kept" "[ '$code' = 200 ] && [ \"\$(windows '$T/crop.exr')\" = \"\$(windows '$T/hao.exr')\" ]"
code=$(post "$PORT_d" "append=1&format=png&$Q" "$T/crop.exr" "$T/e.json")
check "POST append=1&format=png: $code bad_parameter" "[ '$code' = 400 ] && error_is '$T/e.json' bad_parameter"
code=$(post "$PORT_d" "append=1&layer=occ&$Q" "$T/happ.exr" "$T/e2.json")
check "POST append=1 onto occ.Y: $code bad_parameter, naming it" \
    "[ '$code' = 400 ] && error_is '$T/e2.json' bad_parameter && grep -q 'occ.Y' '$T/e2.json'"
code=$(post "$PORT_d" "append=1" "$DATA/deep_small.exr" "$T/e3.json")
check "POST deep with append=1: $code unsupported" "[ '$code' = 415 ] && error_is '$T/e3.json' unsupported"
code=$(post "$PORT_d" "layer=a%01b&$Q" "$T/crop.exr" "$T/e4.json")
check "POST layer with a control character: $code bad_parameter" "[ '$code' = 400 ] && error_is '$T/e4.json' bad_parameter"
if [ -n "$TP" ]; then
    python3 -I -B -c '
import sys; sys.path.insert(0, "clients/python")
import obscura_client as oc
p = dict(fov_y=50, near=0.05, far=100, world_to_camera=sys.argv[3], radius=0.05, append=1, layer="occ")
oc.ao(sys.argv[1], server="tcp://127.0.0.1:" + sys.argv[2], out=sys.argv[4], **p)
' "$T/crop.exr" "$TP" "$W2C" "$T/bapp.exr"
    rc=$?
    check "binary protocol append=1&layer=occ: exit $rc, same bytes as over HTTP" "[ $rc -eq 0 ] && cmp -s '$T/happ.exr' '$T/bapp.exr'"
else
    bad "the daemon's binary port was not found in its log"
fi
"$OBSCURA" ao "$T/crop.exr" --camera "$CAMJ" --radius 0.05 -q --append --layer occ -o "$T/lapp.exr"
for url in "http://127.0.0.1:$PORT_d" "tcp://127.0.0.1:$TP"; do
    "$OBSCURA" ao "$T/crop.exr" --camera "$CAMJ" --radius 0.05 -q --append --layer occ --server "$url" -o "$T/rapp.exr"
    rc=$?
    check "obscura ao --append --server ${url%%:*}: exit $rc, the in-process file's bytes" \
        "[ $rc -eq 0 ] && cmp -s '$T/lapp.exr' '$T/rapp.exr'"
done
code=$($CURL -o "$T/sapp.exr" -w '%{http_code}' -H 'Content-Type: image/x-exr' --data-binary @"$T/crop.exr" \
    "http://127.0.0.1:$PORT_d/v1/streams/s/frames?append=1&layer=occ&$Q")
check "a stream frame posted with append=1&layer=occ: $code, the same bytes as POST /v1/ao's" \
    "[ '$code' = 200 ] && cmp -s '$T/happ.exr' '$T/sapp.exr'"
code=$(get "$PORT_d" "/v1/streams/s/frames/latest?append=0&layer=k" "$T/kept.exr")
check "the kept frame with append=0&layer=k (the post had append=1): $code, the crop's windows, k.Y" \
    "[ '$code' = 200 ] && [ \"\$(windows '$T/crop.exr')\" = \"\$(windows '$T/kept.exr')\" ] && [ \"\$(channels '$T/kept.exr')\" = k.Y ]"
kill "$PID_d" 2>/dev/null
wait "$PID_d" 2>/dev/null

[ $failed -ne 0 ] && tail -20 "$T/d.log" | sed 's/^/       /'
echo "e2e output: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
