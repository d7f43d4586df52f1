#!/bin/sh
# End-to-end tests of obscurad's bake jobs (/v1/bakes): a level posted is
# answered 202 with an id, baked on a worker thread (the result = `obscura
# bake`'s bytes), its state, progress and stage times read back, its
# progress streamed as Server-Sent Events; a cancelled job (running and
# queued), a failed one (bad input), unknown ids (404), bad queries and
# bodies, the job limit, the token; frames are served while a bake runs,
# and SIGTERM during a bake cancels it and the drain ends; a bake with
# lods=2 (the LOD levels of obscura bake --lods 2).
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/bakes.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
FIX=$DATA/levels/aalborg_cut.acc
. tests/e2e/lib/common.sh
CPIDS=""

echo "secret-bake" > "$T/token"
AUTH="Authorization: Bearer secret-bake"
# bpost PORT QUERY FILE OUT: POST a level, prints the status
bpost() {
    $CURL -o "$4" -D "$4.h" -w '%{http_code}' -H "$AUTH" --data-binary @"$3" "http://127.0.0.1:$1/v1/bakes?$2"
}
# bget PORT PATH OUT [curl args]: prints the status
bget() { p=$1 path=$2 o=$3; shift 3; get "$p" "$path" "$o" -H "$AUTH" "$@"; }
field() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval('d'+sys.argv[2]))" "$@" 2>/dev/null; }
id_of() { field "$1" "['id']"; }
# wait_state PORT ID STATE: until the job is in STATE (bounded, 60 s)
wait_state() {
    i=0
    while [ $i -lt 600 ]; do
        bget "$1" "/v1/bakes/$2" "$T/ws" >/dev/null
        s=$(field "$T/ws" "['state']")
        [ "$s" = "$3" ] && return 0
        case "$s" in done|failed|cancelled) [ "$s" != "$3" ] && return 1 ;; esac
        sleep 0.1; i=$((i + 1))
    done
    return 1
}
# wait_for FILE PATTERN: until the file holds the pattern (bounded, 30 s)
wait_for() {
    i=0
    while [ $i -lt 300 ] && ! grep -q "$2" "$1" 2>/dev/null; do sleep 0.1; i=$((i + 1)); done
    grep -q "$2" "$1" 2>/dev/null
}
LONG="rays=8192&samples_per_face=16" # about 16 s of two cores on the fixture: always cancelled, never waited for

echo "e2e bakes: $OBSCURAD"
start S --token-file "$T/token" --max-bakes 2 --bake-workers 1 --bake-keep 8 --max-level 1m
S=$PORT_S

echo "-- a bake job"
"$OBSCURA" bake "$FIX" -o "$T/local.glb" --rays 16 --distances 2,300 -q
code=$(bpost $S "rays=16&distances=2,300" "$FIX" "$T/p1")
ID=$(id_of "$T/p1")
check "POST /v1/bakes: 202, an id, Location /v1/bakes/ID, format told from the bytes (ac)" \
    "[ $code = 202 ] && [ -n '$ID' ] && grep -qi '^Location: /v1/bakes/$ID' $T/p1.h && [ \"\$(field $T/p1 \"['format']\")\" = ac ]"
check "the job ends done" "wait_state $S $ID done"
bget $S "/v1/bakes/$ID" "$T/j1" >/dev/null
check "GET /v1/bakes/ID: progress 1, 811 triangles, 16 rays a sample, the parameters" \
    "[ \"\$(field $T/j1 \"['progress']\")\" = 1 ] && [ \"\$(field $T/j1 \"['counts']['triangles']\")\" = 811 ] && [ \"\$(field $T/j1 \"['counts']['rays']\")\" = \$((16 * \$(field $T/j1 \"['counts']['samples']\"))) ] && [ \"\$(field $T/j1 \"['params']['rays']\")\" = 16 ]"
check "GET /v1/bakes/ID: per-stage times (queued, load, each stage, write)" \
    "field $T/j1 \"['seconds']['queued'] + d['seconds']['load'] + d['seconds']['trace'] + d['seconds']['solve'] + d['seconds']['write']\" >/dev/null"
code=$(bget $S "/v1/bakes/$ID/result" "$T/r1.glb")
check "GET /v1/bakes/ID/result: 200 model/gltf-binary, the bytes of obscura bake" \
    "[ $code = 200 ] && grep -qi 'Content-Type: model/gltf-binary' $T/r1.glb.h && cmp -s $T/r1.glb $T/local.glb"
"$OBSCURA" bake "$FIX" -o "$T/local_lod.glb" --rays 16 --lods 2 -q
code=$(bpost $S "rays=16&lods=2" "$FIX" "$T/p_lod")
ID_LOD=$(id_of "$T/p_lod")
check "a bake job with lods=2 ends done" "[ $code = 202 ] && wait_state $S $ID_LOD done"
code=$(bget $S "/v1/bakes/$ID_LOD/result" "$T/r_lod.glb")
check "... its result: the bytes of obscura bake --lods 2 (MSFT_lod levels)" \
    "[ $code = 200 ] && cmp -s $T/r_lod.glb $T/local_lod.glb && grep -q MSFT_lod $T/r_lod.glb"
echo "-- a decorators file beside the level (multipart/form-data)"
TREES=tests/data/levels/aalborg_cut.trees.json
"$OBSCURA" bake "$FIX" -o "$T/local_dec.glb" --rays 16 --distances 2,300 --decorators "$TREES" -q
# mpost OUT PART...: POST /v1/bakes?rays=16&distances=2,300 with curl -F parts, prints the status
mpost() {
    o=$1; shift
    $CURL -o "$o" -D "$o.h" -w '%{http_code}' -H "$AUTH" "$@" "http://127.0.0.1:$S/v1/bakes?rays=16&distances=2,300"
}
code=$(mpost "$T/p_dec" -F "level=@$FIX" -F "decorators=@$TREES")
ID_DEC=$(id_of "$T/p_dec")
check "POST level and decorators as multipart/form-data: 202, the job ends done" \
    "[ $code = 202 ] && wait_state $S $ID_DEC done"
bget $S "/v1/bakes/$ID_DEC" "$T/jdec" >/dev/null
check "... GET /v1/bakes/ID: the file's rules, 2 tree nodes (as obscura bake --decorators)" \
    "[ \"\$(field $T/jdec \"['decorator_rules']\")\" -gt 0 ] && [ \"\$(field $T/jdec \"['decorator_nodes']['tree']\")\" = 2 ]"
code=$(bget $S "/v1/bakes/$ID_DEC/result" "$T/r_dec.glb")
check "... its result: the bytes of obscura bake --decorators, not those without" \
    "[ $code = 200 ] && cmp -s $T/r_dec.glb $T/local_dec.glb && ! cmp -s $T/r_dec.glb $T/local.glb"
code=$(mpost "$T/p_lvl" -F "level=@$FIX")
ID_LVL=$(id_of "$T/p_lvl")
check "a multipart body with the level alone: the bytes of the plain POST" \
    "[ $code = 202 ] && wait_state $S $ID_LVL done && [ \"\$(bget $S /v1/bakes/$ID_LVL/result $T/r_lvl.glb)\" = 200 ] && cmp -s $T/r_lvl.glb $T/local.glb"
printf 'not json' >"$T/notjson.json"
printf '{"decorators": [{"name": "OBJ1479", "class": "cactus"}]}' >"$T/badclass.json"
code=$(mpost "$T/e1" -F "level=@$FIX" -F "decorators=@$T/notjson.json")
check "decorators that are not JSON: 400 bad_decorators, before any job" \
    "[ $code = 400 ] && grep -q bad_decorators $T/e1 && grep -q 'not JSON' $T/e1"
code=$(mpost "$T/e2" -F "level=@$FIX" -F "decorators=@$T/badclass.json")
check "a rule of an unknown class: 400 naming the entry and the class" \
    "[ $code = 400 ] && grep -q \"decorators\\[0\\]\" $T/e2 && grep -q \"unknown class 'cactus'\" $T/e2"
code=$(mpost "$T/e3" -F "level=@$FIX" -F "trees=@$TREES")
check "an unknown part: 400 bad_multipart naming it" \
    "[ $code = 400 ] && grep -q bad_multipart $T/e3 && grep -q \"unknown part 'trees'\" $T/e3"
# a multipart body cut before its closing boundary (the level part unfinished)
python3 -c "
import sys
lvl = open('$FIX', 'rb').read()
b = b'--XyZ\\r\\nContent-Disposition: form-data; name=\\\"level\\\"; filename=\\\"a.acc\\\"\\r\\n\\r\\n' + lvl[:4000]
open('$T/cut.mp', 'wb').write(b)"
code=$($CURL -o "$T/e5" -w '%{http_code}' -H "$AUTH" -H 'Content-Type: multipart/form-data; boundary=XyZ' \
    --data-binary @"$T/cut.mp" "http://127.0.0.1:$S/v1/bakes?rays=16")
check "a multipart body cut short: 400 bad_multipart" "[ $code = 400 ] && grep -q bad_multipart $T/e5"
head -c 1100000 /dev/zero >"$T/big.bin"
code=$(mpost "$T/e6" -H 'Transfer-Encoding: chunked' -F "level=@$T/big.bin")
check "a chunked multipart body whose level part is over --max-level: 413 body_too_large naming the part" \
    "[ $code = 413 ] && grep -q body_too_large $T/e6 && grep -q 'part level is over' $T/e6"
code=$(mpost "$T/e7" -F "level=@$FIX" -F "level=@$FIX")
check "a part given twice: 400 bad_multipart saying so" "[ $code = 400 ] && grep -q 'part level given twice' $T/e7"
code=$(mpost "$T/e4" -F "decorators=@$TREES")
check "no part level: 400 saying so" "[ $code = 400 ] && grep -q \"without a part 'level'\" $T/e4"
code=$(bget $S "/v1/bakes" "$T/list")
check "GET /v1/bakes lists it" "[ $code = 200 ] && grep -q '\"id\":\"$ID\",\"state\":\"done\"' $T/list"
code=$(bget $S "/v1/bakes/$ID/events" "$T/ev1")
check "events of a finished job: one 'done' event, then the stream ends" \
    "[ $code = 200 ] && grep -qi 'text/event-stream' $T/ev1.h && grep -q '^event: done' $T/ev1 && [ \$(grep -c '^event:' $T/ev1) = 1 ]"

echo "-- a failed job (bad input)"
code=$(bpost $S "" "$DATA/levels/bad/no_triangles.obj" "$T/p2")
ID2=$(id_of "$T/p2")
check "a level without triangles: 202 (told from the bytes: obj), then failed" \
    "[ $code = 202 ] && [ \"\$(field $T/p2 \"['format']\")\" = obj ] && wait_state $S $ID2 failed"
bget $S "/v1/bakes/$ID2" "$T/j2" >/dev/null
check "its error: BAD_FILE, 'no triangles', naming the level, not the daemon's temporary file" \
    "[ \"\$(field $T/j2 \"['error']['status']\")\" = BAD_FILE ] && field $T/j2 \"['error']['message']\" | grep -q '^the level (obj): no triangles' && ! field $T/j2 \"['error']['message']\" | grep -q obscurad-bake"
code=$(bget $S "/v1/bakes/$ID2/result" "$T/r2")
check "its result: 409 bake_failed" "[ $code = 409 ] && error_is $T/r2 bake_failed"

echo "-- a cancelled job, its events, the limit"
code=$(bpost $S "$LONG" "$FIX" "$T/p3")
ID3=$(id_of "$T/p3")
$CURL -N -H "$AUTH" "http://127.0.0.1:$S/v1/bakes/$ID3/events" > "$T/ev3" 2>/dev/null &
CPIDS="$CPIDS $!"
code4=$(bpost $S "$LONG" "$FIX" "$T/p4")
ID4=$(id_of "$T/p4")
code5=$(bpost $S "$LONG" "$FIX" "$T/p5")
check "two long jobs accepted (one worker: the second queued), a third 503 bake_queue_full (--max-bakes 2)" \
    "[ $code = 202 ] && [ $code4 = 202 ] && [ $code5 = 503 ] && error_is $T/p5 bake_queue_full && grep -qi '^Retry-After' $T/p5.h"
check "the first runs: progress events over SSE while it traces" "wait_for $T/ev3 '\"stage\":\"trace\"'"
code=$(post $S "fov_y=50&near=0.05&far=100&samples=4" "$DATA/room_small.exr" "$T/frame.exr" -H "$AUTH")
bget $S "/v1/bakes/$ID3" "$T/j3" >/dev/null
check "a frame is served while the bake runs (200; the bake still running)" \
    "[ $code = 200 ] && [ \"\$(field $T/j3 \"['state']\")\" = running ]"
code=$(bget $S "/v1/bakes/$ID3/result" "$T/r3")
check "a running job's result: 409 bake_not_done" "[ $code = 409 ] && error_is $T/r3 bake_not_done"
code=$(bget $S "/v1/bakes/$ID4" "$T/j4" -X DELETE)
check "DELETE a queued job: 200, cancelled at once" \
    "[ $code = 200 ] && [ \"\$(field $T/j4 \"['state']\")\" = cancelled ] && wait_state $S $ID4 cancelled"
code=$(bget $S "/v1/bakes/$ID3" "$T/d3" -X DELETE)
check "DELETE the running job: 200, cancel requested" "[ $code = 200 ] && grep -q '\"cancel_requested\":true' $T/d3"
t0=$(date +%s)
check "it ends cancelled, within a second or two (between batches of rays)" \
    "wait_state $S $ID3 cancelled && [ \$((\$(date +%s) - t0)) -le 3 ]"
bget $S "/v1/bakes/$ID3" "$T/j3" >/dev/null
check "its state: cancelled, short of every sample, error CANCELLED" \
    "[ \"\$(field $T/j3 \"['error']['status']\")\" = CANCELLED ] && python3 -c \"import json; d=json.load(open('$T/j3')); assert 0 < d['samples_done'] < d['samples']\""
check "its event stream ends with a 'cancelled' event" "wait_for $T/ev3 '^event: cancelled'"
code=$(bget $S "/v1/bakes/$ID3/result" "$T/r3")
check "its result: 409 bake_cancelled" "[ $code = 409 ] && error_is $T/r3 bake_cancelled"
code=$(bget $S "/v1/bakes/$ID" "$T/d1" -X DELETE)
code2=$(bget $S "/v1/bakes/$ID" "$T/g1")
check "DELETE a finished job: removed; then it is 404" \
    "[ $code = 200 ] && grep -q '\"removed\":true' $T/d1 && [ $code2 = 404 ] && error_is $T/g1 not_found"

echo "-- unknown ids, bad requests"
for p in /v1/bakes/0123456789abcdef /v1/bakes/0123456789abcdef/result /v1/bakes/0123456789abcdef/events; do
    code=$(bget $S "$p" "$T/u")
    check "GET $p: 404 not_found, 'restart loses them'" "[ $code = 404 ] && error_is $T/u not_found && grep -q 'restart loses them' $T/u"
done
code=$(bget $S /v1/bakes/0123456789abcdef "$T/u" -X DELETE)
check "DELETE an unknown job: 404" "[ $code = 404 ] && error_is $T/u not_found"
code=$(bget $S /v1/bakes/not-an-id "$T/u")
check "an id that is not hex: 404" "[ $code = 404 ] && error_is $T/u not_found"
code=$(bget $S /v1/bakes/0123456789abcdef/nope "$T/u")
check "no such route under /v1/bakes: 404" "[ $code = 404 ] && error_is $T/u not_found"
code=$(bpost $S "rays=0" "$FIX" "$T/u")
check "rays=0: 400 bad_parameter naming it" "[ $code = 400 ] && error_is $T/u bad_parameter && grep -q 'rays' $T/u"
code=$(bpost $S "nope=1" "$FIX" "$T/u")
check "an unknown parameter: 400" "[ $code = 400 ] && error_is $T/u bad_parameter && grep -q \"unknown bake parameter 'nope'\" $T/u"
code=$(bpost $S "format=../x" "$FIX" "$T/u")
check "format=../x: 400" "[ $code = 400 ] && error_is $T/u bad_parameter"
code=$(bpost $S "distances=2" "$FIX" "$T/u")
check "distances=2: 400 (SHORT,LONG)" "[ $code = 400 ] && grep -q 'SHORT,LONG' $T/u"
head -c 3000 /dev/urandom | tr -d 'vog#{' > "$T/noise"; printf '\001' | cat - "$T/noise" > "$T/noise1"
code=$(bpost $S "" "$T/noise1" "$T/u")
check "a body of unknown format: 415, 'give format=EXT'" "[ $code = 415 ] && grep -q 'format=EXT' $T/u"
: > "$T/empty"
code=$(bpost $S "" "$T/empty" "$T/u")
check "an empty body: 400 empty_body" "[ $code = 400 ] && error_is $T/u empty_body"
head -c 1100000 /dev/zero > "$T/big"
code=$(bpost $S "" "$T/big" "$T/u")
check "a level over --max-level (1m): 413 before reading" "[ $code = 413 ] && error_is $T/u body_too_large && grep -q 'max-level' $T/u"
code=$(bget $S /v1/bakes "$T/u" -X PUT)
check "PUT /v1/bakes: 405 with Allow" "[ $code = 405 ] && grep -qi '^Allow: GET, POST' $T/u.h"
code=$(get $S /v1/bakes "$T/u")
code2=$($CURL -o "$T/u2" -w '%{http_code}' --data-binary @"$FIX" "http://127.0.0.1:$S/v1/bakes")
check "no token: 401 for GET and POST" "[ $code = 401 ] && [ $code2 = 401 ] && error_is $T/u unauthorized"
get $S /metrics "$T/m" -H "$AUTH" >/dev/null
check "metrics: /v1/bakes requests by code" "grep -q 'route=\"/v1/bakes\",code=\"202\"' $T/m && grep -q 'route=\"/v1/bakes\",code=\"404\"' $T/m"

echo "-- SIGTERM during a bake"
code=$(bpost $S "$LONG" "$FIX" "$T/p6")
ID6=$(id_of "$T/p6")
$CURL -N -H "$AUTH" "http://127.0.0.1:$S/v1/bakes/$ID6/events" > "$T/ev6" 2>/dev/null &
CPIDS="$CPIDS $!"
wait_for "$T/ev6" '"stage":"trace"'
t0=$(date +%s)
kill -TERM "$PID_S"
wait "$PID_S"; rc=$?
check "the daemon exits 0 within 3 s, the running bake cancelled, its stream ended" \
    "[ $rc = 0 ] && [ \$((\$(date +%s) - t0)) -le 3 ] && grep -q 'bake=$ID6 cancelled' $T/S.log && wait_for $T/ev6 '^event: end'"

echo "-- a baked G-buffer's _AO combined by the daemon (baked=, baked_combine=)"
"$OBSCURA" bake "$FIX" -o "$T/lv.glb" --rays 16 -q &&
    python3 tools/level_cameras.py "$T/lv.glb" "$T" 1 160 120 >/dev/null &&
    "$OBSCURA" gbuffer "$T/lv.glb" --camera "$T/cam0.json" -o "$T/lg.exr" -q
"$OBSCURA" ao "$T/lg.exr" -o "$T/lc.exr" --radius 2 -q
start B
code=$(post $PORT_B "radius=2&float=1" "$T/lg.exr" "$T/b1.exr")
m=$("$OBSCURA" compare "$T/lc.exr" "$T/b1.exr" --json 2>/dev/null | sed -n 's/.*"mse": \([-0-9.e+]*\).*/\1/p')
mb=$("$OBSCURA" compare "$T/lc.exr" "$T/b1.exr" --channel-a AOBaked.Y --channel-b AOBaked.Y --json 2>/dev/null |
    sed -n 's/.*"mse": \([-0-9.e+]*\).*/\1/p')
ms=$("$OBSCURA" compare "$T/lc.exr" "$T/b1.exr" --channel-a AOScreen.Y --channel-b AOScreen.Y --json 2>/dev/null |
    sed -n 's/.*"mse": \([-0-9.e+]*\).*/\1/p')
check "POST /v1/ao of a baked G-buffer: AO.Y, AOScreen.Y, AOBaked.Y as obscura ao writes them (MSE $m, $ms, $mb)" \
    "[ $code = 200 ] && [ -n '$m' ] && awk 'BEGIN { exit !($m < 1e-6 && $ms < 1e-6 && $mb < 1e-6) }'"
code=$(post $PORT_B "radius=2&float=1&baked=none" "$T/lg.exr" "$T/b2.exr")
m=$("$OBSCURA" compare "$T/lc.exr" "$T/b2.exr" --channel-a AOScreen.Y --json 2>/dev/null | sed -n 's/.*"mse": \([-0-9.e+]*\).*/\1/p')
check "baked=none: the chain's AO alone, no AOBaked.Y (MSE against AOScreen.Y $m)" \
    "[ $code = 200 ] && awk 'BEGIN { exit !($m < 1e-6) }' && ! '$OBSCURA' compare '$T/b2.exr' '$T/b2.exr' --channel-a AOBaked.Y >/dev/null 2>&1"
code=$(post $PORT_B "radius=2&baked=_AO_LONG&baked_combine=min" "$T/lg.exr" "$T/b3.exr")
"$OBSCURA" ao "$T/lg.exr" -o "$T/lc3.exr" --radius 2 --baked _AO_LONG --baked-combine min -q
m=$("$OBSCURA" compare "$T/lc3.exr" "$T/b3.exr" --json 2>/dev/null | sed -n 's/.*"mse": \([-0-9.e+]*\).*/\1/p')
check "baked=_AO_LONG&baked_combine=min as the CLI's (MSE $m, half floats)" \
    "[ $code = 200 ] && awk 'BEGIN { exit !($m < 1e-5) }'"
code=$(post $PORT_B "radius=2&baked=_AO_MID" "$T/lg.exr" "$T/b4.json")
check "baked naming no channel: 422 naming it ($code)" \
    "[ $code = 422 ] && grep -q '_AO_MID' $T/b4.json"
code=$(post $PORT_B "radius=2" "$DATA/room_small.exr" "$T/b5.exr")
check "a G-buffer without _AO: not combined, no AOBaked.Y ($code)" \
    "[ $code = 200 ] && ! '$OBSCURA' compare '$T/b5.exr' '$T/b5.exr' --channel-a AOBaked.Y >/dev/null 2>&1"
kill -TERM "$PID_B"; wait "$PID_B"

echo "-- bakes off"
start O --max-bakes 0
code=$(get $PORT_O /v1/bakes "$T/u")
check "--max-bakes 0: 404 bakes_off" "[ $code = 404 ] && error_is $T/u bakes_off"
kill -TERM "$PID_O"; wait "$PID_O"

echo "e2e bakes: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
