#!/bin/sh
# End-to-end tests of obscurad's streams (/v1/streams): frames posted to a
# stream are answered like /v1/ao and kept (bounded, oldest dropped),
# fetched again as AO / composite / colour, re-run with other parameters,
# announced to Server-Sent Events subscribers; bad requests get JSON
# errors; an open event stream does not hold up the SIGTERM drain; the
# preview page is served.  `obscura ao --stream` posts to a stream.
# Deep frames are kept and viewed like flat ones (the front layer's AO,
# output=ao_front); each frame's JSON carries its parameters and camera;
# a failed stream post still writes the CLI's result.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/streams.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
. tests/e2e/lib/common.sh
CPIDS=""

W2C=$(tr -d ' \n' < "$DATA/room_small.camera.json" |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
CAM="fov_y=50&near=0.05&far=100&world_to_camera=$W2C"

# spost PORT STREAM QUERY OUT: POST a frame to a stream, prints the status
spost() {
    $CURL -o "$4" -D "$4.h" -w '%{http_code}' -H 'Content-Type: image/x-exr' \
        --data-binary @"$R" "http://127.0.0.1:$1/v1/streams/$2/frames?$3"
}
# wait_for FILE PATTERN: until the file holds the pattern (bounded, 10 s)
wait_for() {
    i=0
    while [ $i -lt 100 ] && ! grep -q "$2" "$1" 2>/dev/null; do sleep 0.1; i=$((i + 1)); done
    grep -q "$2" "$1" 2>/dev/null
}

echo "e2e streams: $OBSCURAD"
start S --stream-frames 3 --streams 2 --queue 4
S=$PORT_S

echo "-- the page"
check "GET / is the preview page" "[ \$(get $S / $T/g) = 200 ] && grep -qi 'Content-Type: text/html' $T/g.h && grep -q 'preview/app.js' $T/g"
check "GET /preview/app.js and style.css" "[ \$(get $S /preview/app.js $T/g) = 200 ] && grep -qi 'javascript' $T/g.h && [ \$(get $S /preview/style.css $T/g) = 200 ]"
check "GET /preview/nope 404 JSON" "[ \$(get $S /preview/nope $T/g) = 404 ] && error_is $T/g not_found"

echo "-- posting frames, events"
$CURL -N "http://127.0.0.1:$S/v1/streams/shot/events" > "$T/sse" 2>/dev/null &
CPIDS="$CPIDS $!"
wait_for "$T/S.log" "events status=200" || true
"$OBSCURA" ao "$R" --fov-y 50 --near 0.05 --far 100 --world-to-camera "$W2C" -o "$T/local.exr" -q
# the daemon answers RLE unless asked (compression auto): obscura ao writes those bytes with --compression rle
"$OBSCURA" ao "$R" --fov-y 50 --near 0.05 --far 100 --world-to-camera "$W2C" --compression rle -o "$T/local_rle.exr" -q
code=$(spost $S shot "$CAM" "$T/f1.exr")
check "POST /v1/streams/shot/frames: 200, X-Obscura-Frame 1, Server-Timing" "[ $code = 200 ] && grep -qi '^X-Obscura-Frame: 1' $T/f1.exr.h && grep -qi '^Server-Timing: queue' $T/f1.exr.h"
check "its answer = POST /v1/ao's (same EXR bytes as in-process)" "cmp -s $T/f1.exr $T/local_rle.exr"
check "subscriber told: event frame 1 with size, flat, timings" "wait_for $T/sse 'event: frame' && grep -q '\"frame\":1,\"width\":320,\"height\":240,\"color\":true,\"deep\":false,\"timings\":{\"queue\"' $T/sse"
code=$(spost $S shot "$CAM&radius=1.5&output=composite&format=png" "$T/f2.png")
check "second frame as composite PNG: 200, frame 2" "[ $code = 200 ] && grep -qi '^X-Obscura-Frame: 2' $T/f2.png.h && grep -qi 'image/png' $T/f2.png.h"
check "subscriber told: frame 2" "wait_for $T/sse '\"frame\":2'"
check "GET /v1/streams lists shot with frames 1, 2" "[ \$(get $S /v1/streams $T/g) = 200 ] && tr -d ' \t\n' < $T/g | grep -q '\"name\":\"shot\",\"frames\":\[1,2\],\"latest\":2'"
check "GET /v1/streams/shot: frames with params and timings" "[ \$(get $S /v1/streams/shot $T/g) = 200 ] && grep -q '\"radius\":.*\"1.5\"' $T/g && grep -q '\"gl\"' $T/g"
# the page's controls show these: each frame's own query (snake_case
# names) and the camera it ran with, not the table's defaults
tr -d ' \t\n' < "$T/g" > "$T/gj"
check "frame 1's JSON: flat, params fov_y 50 near 0.05 far 100 (radius absent)" "grep -q '\"frame\":1,[^}]*\"deep\":false' $T/gj && grep -q '\"params\":{\"fov_y\":\"50\",\"near\":\"0.05\",\"far\":\"100\",\"world_to_camera\":\"[^\"]*\"}}' $T/gj"
code=$($CURL -o "$T/fy.exr" -w '%{http_code}' -H 'Content-Type: image/x-exr' --data-binary @"$R" \
    "http://127.0.0.1:$S/v1/streams/fy/frames?fov-y=40&fov-y=45&samples=4")
check "params keyed by the table's names, the last given wins (fov-y=40&fov-y=45: fov_y 45)" "[ $code = 200 ] && [ \$(get $S /v1/streams/fy $T/g) = 200 ] && tr -d ' \t\n' < $T/g | grep -q '\"params\":{\"fov_y\":\"45\",\"samples\":\"4\"}'"

echo "-- deep frames"
DP=$DATA/deep_small.exr
$CURL -N "http://127.0.0.1:$S/v1/streams/fy/events" > "$T/dsse" 2>/dev/null &
CPIDS="$CPIDS $!"
wait_for "$T/S.log" "fy/events status=200" || true
code=$($CURL -o "$T/d1.exr" -D "$T/d1.exr.h" -w '%{http_code}' -H 'Content-Type: image/x-exr' --data-binary @"$DP" \
    "http://127.0.0.1:$S/v1/streams/fy/frames?deep_layers=3")
post $S "deep_layers=3" "$DP" "$T/dao.exr" >/dev/null
check "a deep EXR posted to a stream: 200, frame 2, kept" "[ $code = 200 ] && grep -qi '^X-Obscura-Frame: 2' $T/d1.exr.h && [ \$(get $S /v1/streams/fy/frames/2?format=exr $T/dk.exr) = 200 ]"
check "its answer and its kept EXR = POST /v1/ao's for the same deep body (AO.Y, AOFront.Y, R,G,B,A)" "cmp -s $T/d1.exr $T/dao.exr && cmp -s $T/dk.exr $T/dao.exr"
check "subscriber told: the frame is deep" "wait_for $T/dsse '\"frame\":2,' && grep -q '\"frame\":2,\"width\":48,\"height\":32,\"color\":false,\"deep\":true' $T/dsse"
check "GET /v1/streams/fy: frame 2 deep, its params, the camera of its file (fov_y 40, near 0.1)" "[ \$(get $S /v1/streams/fy $T/g) = 200 ] && tr -d ' \t\n' < $T/g | grep -q '\"frame\":2,[^}]*\"deep\":true,.*\"params\":{\"deep_layers\":\"3\"},\"camera\":{\"fov_y\":40,\"near\":0.1,'"
"$OBSCURA" ao "$DP" --deep-layers 3 -o "$T/dl.png" -q 2>/dev/null
code=$(get $S "/v1/streams/fy/frames/2?output=ao_front&format=png" "$T/df.png")
check "output=ao_front: the front layer's AO (= obscura ao's .front.png)" "[ $code = 200 ] && cmp -s $T/df.png $T/dl.front.png"
code=$(get $S "/v1/streams/fy/frames/2?output=composite&format=png&exposure=1" "$T/dc.png")
check "output=composite with exposure: 200 PNG" "[ $code = 200 ] && grep -qi 'image/png' $T/dc.png.h"
code=$(get $S "/v1/streams/fy/frames/2?output=color&format=png" "$T/g")
check "output=color on a deep frame: 404 no_color, says it is deep" "[ $code = 404 ] && error_is $T/g no_color && grep -q 'deep frame has no flat colour' $T/g"
"$OBSCURA" ao "$DP" --deep-layers 3 --radius 2 --compression rle -o "$T/dl2.exr" -q 2>/dev/null
code=$(get $S "/v1/streams/fy/frames/2?radius=2&format=exr" "$T/dr.exr")
code2=$(get $S "/v1/streams/fy/frames/2?radius=2&output=ao_front&format=png" "$T/drf.png")
check "a re-run of the deep frame (radius 2) = in-process; its front AO too" "[ $code = 200 ] && [ $code2 = 200 ] && cmp -s $T/dr.exr $T/dl2.exr && ! cmp -s $T/drf.png $T/df.png"
code=$(get $S "/v1/streams/fy/frames/1?output=ao_front&format=png" "$T/g")
check "output=ao_front on a flat frame: 400 not_deep" "[ $code = 400 ] && error_is $T/g not_deep"

echo "-- kept frames"
code=$(get $S "/v1/streams/shot/frames/1?format=exr" "$T/k1.exr")
check "frames/1 as EXR = the answer to its POST" "[ $code = 200 ] && cmp -s $T/k1.exr $T/f1.exr"
code=$(get $S "/v1/streams/shot/frames/latest?output=composite&format=png" "$T/k2.png")
check "frames/latest composite PNG = the answer to its POST" "[ $code = 200 ] && cmp -s $T/k2.png $T/f2.png && grep -qi '^X-Obscura-Frame: 2' $T/k2.png.h"
code=$(get $S "/v1/streams/shot/frames/2?output=color&format=png" "$T/c0.png")
code2=$(get $S "/v1/streams/shot/frames/2?output=color&format=png&exposure=2" "$T/c2.png")
check "output=color: the G-buffer's colour; exposure changes it" "[ $code = 200 ] && [ $code2 = 200 ] && ! cmp -s $T/c0.png $T/c2.png"
code=$(get $S "/v1/streams/shot/frames/1?radius=1.5&format=exr" "$T/r1.exr")
"$OBSCURA" ao "$R" --fov-y 50 --near 0.05 --far 100 --world-to-camera "$W2C" --radius 1.5 --compression rle -o "$T/local15.exr" -q
check "a parameter re-runs frame 1 with it (= in-process radius 1.5), Server-Timing" "[ $code = 200 ] && cmp -s $T/r1.exr $T/local15.exr && grep -qi '^Server-Timing: queue' $T/r1.exr.h"
code=$(get $S "/v1/streams/shot/frames/1?format=exr" "$T/k1b.exr")
check "the re-run is not kept: frame 1 unchanged" "[ $code = 200 ] && cmp -s $T/k1b.exr $T/f1.exr"

echo "-- bounds: 3 frames per stream, 2 streams"
for i in 3 4; do spost $S shot "$CAM&samples=4" "$T/x" >/dev/null; done
check "after 4 frames, 3 kept (2, 3, 4): frame 1 is 404" "[ \$(get $S /v1/streams/shot/frames/1 $T/g) = 404 ] && error_is $T/g not_found && [ \$(get $S /v1/streams/shot/frames/2 $T/g) = 200 ]"
spost $S b "$CAM&samples=4" "$T/x" >/dev/null
spost $S c "$CAM&samples=4" "$T/x" >/dev/null
check "a third stream drops the least recently posted-to (shot)" "[ \$(get $S /v1/streams/shot $T/g) = 404 ] && [ \$(get $S /v1/streams/c $T/g) = 200 ]"
check "shot's subscriber is told (event end) and its stream closed" "wait_for $T/sse 'event: end' && grep -q 'stream dropped' $T/sse"
get $S /metrics "$T/m" >/dev/null
check "metrics: streams, kept frames, bytes, subscribers" "grep -q '^obscurad_streams 2' $T/m && grep -q '^obscurad_stream_frames 2' $T/m && grep -q '^obscurad_stream_bytes [1-9]' $T/m && grep -q '^obscurad_event_subscribers' $T/m && grep -q 'route=\"/v1/streams\",code=\"200\"' $T/m"

echo "-- errors"
check "bad stream name: 400 JSON" "[ \$(get $S '/v1/streams/b%40d' $T/g) = 400 ] && error_is $T/g bad_stream_name"
check "unknown stream: 404" "[ \$(get $S /v1/streams/nobody/frames/latest $T/g) = 404 ] && error_is $T/g not_found"
check "no such sub-route: 404" "[ \$(get $S /v1/streams/c/whatever $T/g) = 404 ] && error_is $T/g not_found"
check "frame 0 / not a number: 404" "[ \$(get $S /v1/streams/c/frames/0 $T/g) = 404 ] && [ \$(get $S /v1/streams/c/frames/x1 $T/g) = 404 ]"
check "subscribing to an unknown stream when --streams are full: 503, nothing dropped" "[ \$(get $S /v1/streams/zzz/events $T/g) = 503 ] && error_is $T/g too_many_subscribers && [ \$(get $S /v1/streams/c $T/g) = 200 ] && [ \$(get $S /v1/streams/b $T/g) = 200 ]"
check "GET .../frames: 405 Allow POST" "[ \$(get $S /v1/streams/c/frames $T/g) = 405 ] && grep -qi '^Allow: POST' $T/g.h"
check "POST .../frames/1: 405 Allow GET" "[ \$($CURL -o $T/g -D $T/g.h -w '%{http_code}' -X POST http://127.0.0.1:$S/v1/streams/c/frames/1) = 405 ]"
check "bad parameter on a re-run: 400 names it" "[ \$(get $S '/v1/streams/c/frames/latest?radius=-1' $T/g) = 400 ] && error_is $T/g bad_parameter && grep -q radius $T/g"
check "bad exposure: 400" "[ \$(get $S '/v1/streams/c/frames/latest?output=color&exposure=99' $T/g) = 400 ] && grep -q exposure $T/g"
code=$(spost $S c "samples=4&solve_camera=0" "$T/e")
check "a frame without camera: 422, not kept" "[ $code = 422 ] && error_is $T/e no_camera && tr -d ' \t\n' < \$(get $S /v1/streams/c $T/g >/dev/null; echo $T/g) | grep -q '\"frames\":\[1\]'"
code=$($CURL -o "$T/e" -w '%{http_code}' -X POST "http://127.0.0.1:$S/v1/streams/c/frames?$CAM")
check "an empty body: 400 empty_body" "[ $code = 400 ] && error_is $T/e empty_body"
check "daemon serves on: POST /v1/ao 200" "[ \$(post $S '$CAM&samples=4' $R $T/x) = 200 ]"

echo "-- the CLI posts to a stream"
"$OBSCURA" ao "$R" --fov-y 50 --near 0.05 --far 100 --world-to-camera "$W2C" -o "$T/cli.exr" -q \
    --stream cli --server "http://127.0.0.1:$S"
rc=$?
check "obscura ao --stream cli --server: exit $rc, same file, frame kept" "[ $rc -eq 0 ] && cmp -s $T/cli.exr $T/local.exr && [ \$(get $S /v1/streams/cli/frames/1 $T/g) = 200 ]"
"$OBSCURA" ao "$R" --fov-y 50 -o "$T/x.exr" -q --stream cli 2>"$T/err"
check "--stream without --server: exit 2" "[ $? -eq 2 ]"
"$OBSCURA" ao "$R" --fov-y 50 -o "$T/x.exr" -q --stream 'b@d' --server "http://127.0.0.1:$S" 2>"$T/err"
check "--stream with a bad name: exit 2" "[ $? -eq 2 ]"
"$OBSCURA" ao "$DP" --deep-layers 3 --compression rle -o "$T/cd.exr" -q --stream cli --server "http://127.0.0.1:$S" 2>"$T/err"
rc=$?
check "obscura ao DEEP --stream cli: exit $rc (0), = in-process, kept as deep frame 2" "[ $rc -eq 0 ] && cmp -s $T/cd.exr $T/dao.exr && [ \$(get $S /v1/streams/cli $T/g) = 200 ] && tr -d ' \t\n' < $T/g | grep -q '\"frame\":2,[^}]*\"deep\":true'"

echo "-- SIGTERM with event streams open"
$CURL -N "http://127.0.0.1:$S/v1/streams/c/events" > "$T/sse2" 2>/dev/null &
C1=$!
$CURL -N "http://127.0.0.1:$S/v1/streams/cli/events" > "$T/sse3" 2>/dev/null &
C2=$!
CPIDS="$CPIDS $C1 $C2"
wait_for "$T/sse2" "event: frame"
wait_for "$T/S.log" "cli/events status=200"
kill -TERM "$PID_S"
k=0
while [ $k -lt 100 ] && kill -0 "$PID_S" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
wait "$PID_S"; rc=$?
check "exit $rc (0) within 10 s; subscribers told 'shutting down'" "[ $rc -eq 0 ] && grep -q 'shutting down' $T/sse2 && grep -q 'shutting down' $T/sse3"

echo "-- streams off"
start Z --streams 0
check "--streams 0: 404 streams_off" "[ \$(get $PORT_Z /v1/streams $T/g) = 404 ] && error_is $T/g streams_off"
"$OBSCURA" ao "$R" --fov-y 50 --near 0.05 --far 100 --world-to-camera "$W2C" -o "$T/off.exr" -q \
    --stream cli --server "http://127.0.0.1:$PORT_Z" 2>"$T/err"
rc=$?
check "--stream to a daemon with streams off: exit $rc (0), the output written (= in-process), a warning says the post failed" "[ $rc -eq 0 ] && cmp -s $T/off.exr $T/local.exr && grep -q '^obscura: warning: --stream cli: the stream post failed (HTTP 404: streams are off' $T/err"
[ $failed -ne 0 ] && tail -5 "$T/S.log" | sed 's/^/       /'
echo "e2e streams: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
