#!/bin/sh
# End-to-end tests of deep input on obscurad: the deep EXR fixture in
# process, and over the Unix socket and TCP (a deep G-buffer: per-pixel
# counts and samples) and HTTP (the deep EXR as the body) gives the same
# bytes; bad deep frames (counts that do not sum, too many samples,
# unsorted lists, sizes that do not add up, a damaged deep EXR) get a clear
# error and the daemon keeps serving.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/deep.sh
#
# Every daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
D=tests/data/deep_small.exr
. tests/e2e/lib/common.sh
PID=""
SOCK="$T/obscurad.sock"

echo "e2e deep: $OBSCURAD"
: > "$T/d.log"
"$OBSCURAD" --http 127.0.0.1:0 --socket "$SOCK" --tcp 127.0.0.1:0 --max-body 8m --queue 4 2>"$T/d.log" &
PID=$!
i=0; HP=""; TP=""
while [ $i -lt 300 ] && { [ -z "$HP" ] || [ -z "$TP" ]; }; do
    HP=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    TP=$(sed -n 's/.*binary protocol on tcp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    kill -0 "$PID" 2>/dev/null || break
    sleep 0.1
    i=$((i + 1))
done
if [ -n "$HP" ] && [ -n "$TP" ] && [ -S "$SOCK" ]; then ok "obscurad on http :$HP, tcp :$TP and unix:$SOCK"; else
    bad "obscurad did not start"; tail -5 "$T/d.log"; exit 1; fi

echo "-- the same deep frame everywhere"
"$OBSCURA" ao "$D" --output both --deep-layers 3 -o "$T/local.exr" -q 2>/dev/null
"$OBSCURA" ao "$D" --output both --deep-layers 3 -o "$T/local.png" -q 2>/dev/null
for url in "unix:$SOCK" "tcp://127.0.0.1:$TP" "http://127.0.0.1:$HP"; do
    "$OBSCURA" ao "$D" --output both --deep-layers 3 -o "$T/r.exr" --server "$url" -q 2>"$T/err"
    rc=$?
    check "deep over ${url%%:*}: exit $rc, AO.Y, AOFront.Y and the composite: same EXR bytes as in-process" \
        "[ $rc -eq 0 ] && cmp -s '$T/local.exr' '$T/r.exr'"
done
"$OBSCURA" ao "$D" --output both --deep-layers 3 -o "$T/r.png" --server "unix:$SOCK" -q 2>/dev/null
check "deep over unix: the three PNGs = in-process" \
    "cmp -s '$T/local.ao.png' '$T/r.ao.png' && cmp -s '$T/local.front.png' '$T/r.front.png' && cmp -s '$T/local.composite.png' '$T/r.composite.png'"
"$OBSCURA" ao "$D" --deep-mode single --deep-hull thin -o "$T/l2.exr" -q 2>/dev/null
"$OBSCURA" ao "$D" --deep-mode single --deep-hull thin -o "$T/r2.exr" --server "tcp://127.0.0.1:$TP" -q 2>/dev/null
check "the deep parameters travel: single layer, thin hulls over tcp = in-process" "cmp -s '$T/l2.exr' '$T/r2.exr' && ! cmp -s '$T/l2.exr' '$T/local.exr'"
st=$(post "$HP" "output=ao&format=png" "$D" "$T/h.png")
check "curl: POST /v1/ao with a deep EXR, format=png: 200, an image/png" "[ '$st' = 200 ] && grep -qi 'content-type: image/png' '$T/h.png.h'"
st=$($CURL -o "$T/s.json" -w '%{http_code}' -H 'Content-Type: image/x-exr' --data-binary @"$D" "http://127.0.0.1:$HP/v1/streams/deep/frames")
check "a deep EXR posted to a stream: 200, kept (streams.sh checks more) ($st)" "[ '$st' = 200 ] && [ \$(get $HP /v1/streams/deep/frames/1 $T/s2) = 200 ]"
head -c 3000 "$D" > "$T/cut.exr"
st=$(post "$HP" "" "$T/cut.exr" "$T/cut.json")
check "a deep EXR cut short on HTTP: 422 bad_file ($st)" "[ '$st' = 422 ] && error_is '$T/cut.json' bad_file"
"$OBSCURA" ao "$D" -o "$T/x.exr" --server "unix:$SOCK" --deep-layers 9 -q 2>"$T/err"
check "a bad deep parameter: exit 2 before sending" "[ $? -eq 2 ]"

echo "-- bad deep frames: an error answer, the daemon keeps serving"
if command -v python3 >/dev/null 2>&1; then
    # deepframe.py CASE TARGET: builds a deep G-buffer frame (2 x 2, counts
    # 2, 0, 1, 3), spoils it as CASE says, sends it and prints the answer's
    # status and message
    cat > "$T/deepframe.py" <<'EOF2'
import socket, struct, sys
case, target = sys.argv[1], sys.argv[2]
w, h, counts = 2, 2, [2, 0, 1, 3]
total = sum(counts)
samples = []
for k in range(total):
    samples += [2.0 + k, 2.0 + k, 0.5, 0.5, 0.5, 1.0, 0.0, 0.0, 0.0]
values, flags = 9, 2 | 8
proj = [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, -1.0, -0.2, 0, 0, -1.0, 0]
if case == "sum":       counts[1] = 1
if case == "many":      total = 1 << 40
if case == "values":    values = 7
if case == "unsorted":  samples[3 * 9] = 9.0
if case == "pixel":     counts[0] = 70000
hdr = struct.pack("<IIiiiiIIIIQ", w, h, 0, 0, w, h, flags, values, 0, 0, total)
hdr += struct.pack("<16f", *([0.0] * 16)) + struct.pack("<16f", *proj)
body = struct.pack("<%dI" % len(counts), *counts) + struct.pack("<%df" % len(samples), *samples)
if case == "short":     body = body[:-5]
p = struct.pack("<I", 0) + b"\x04" + b"\0" * 3 + hdr + body
data = b"OBSP" + struct.pack("<HHQQ", 1, 1, 9, len(p)) + p
if target.startswith("unix:"):
    s = socket.socket(socket.AF_UNIX); s.connect(target[5:])
else:
    host, port = target.rsplit(":", 1); s = socket.create_connection((host, int(port)))
s.settimeout(20)
s.sendall(data)
buf = b""
try:
    while len(buf) < 30 or len(buf) < 24 + struct.unpack_from("<Q", buf, 16)[0]:
        b = s.recv(65536)
        if not b: break
        buf += b
except socket.timeout:
    print("timeout"); sys.exit(0)
if len(buf) < 30 or buf[:4] != b"OBSP":
    print("EOF"); sys.exit(0)
status, retry, cl = struct.unpack_from("<HHH", buf, 24)
ml, = struct.unpack_from("<I", buf, 30 + cl)
print(status, buf[34 + cl:34 + cl + ml].decode())
EOF2
    # status_is CODE: the last answer's status
    status_is() { [ "$(cut -d' ' -f1 "$T/st")" = "$1" ]; }
    python3 "$T/deepframe.py" good "unix:$SOCK" > "$T/st"; st=$(cat "$T/st")
    check "a hand-made deep frame: 200 ($st)" "status_is 200"
    python3 "$T/deepframe.py" sum "unix:$SOCK" > "$T/st"; st=$(cat "$T/st")
    check "counts that do not sum to the total: 422, says so ($st)" "status_is 422 && grep -q 'sum to 7 samples, the header says 6' '$T/st'"
    python3 "$T/deepframe.py" many "127.0.0.1:$TP" > "$T/st"; st=$(cat "$T/st")
    check "2^40 samples: 413 from the header ($st)" "status_is 413 && grep -q 'over the limit' '$T/st'"
    python3 "$T/deepframe.py" pixel "unix:$SOCK" > "$T/st"; st=$(cat "$T/st")
    check "a pixel of 70000 samples: refused ($st)" "status_is 413 || status_is 422"
    python3 "$T/deepframe.py" values "unix:$SOCK" > "$T/st"; st=$(cat "$T/st")
    check "7 values per sample: 422, names the layout ($st)" "status_is 422 && grep -q '7 values per sample' '$T/st'"
    python3 "$T/deepframe.py" unsorted "unix:$SOCK" > "$T/st"; st=$(cat "$T/st")
    check "a list not sorted front to back: 422 ($st)" "status_is 422 && grep -q 'not sorted by Z' '$T/st'"
    python3 "$T/deepframe.py" short "unix:$SOCK" > "$T/st"; st=$(cat "$T/st")
    check "samples 5 bytes short of the counts: 422 ($st)" "status_is 422 && grep -q 'the frame holds' '$T/st'"
else
    echo "  skip bad-frame checks: no python3"
fi
"$OBSCURA" ao "$D" --output both --deep-layers 3 -o "$T/again.exr" --server "unix:$SOCK" -q 2>/dev/null
check "still serving after the bad deep frames: same bytes" "cmp -s '$T/local.exr' '$T/again.exr' && kill -0 $PID"

echo "-- gtao on a deep G-buffer with facing flags: the exact slice integral by default"
# a wall and a thin plate in front of it, closed boxes (front and back faces)
box() { # x0 x1 y0 y1 z0 z1 first-vertex-index
    for x in $1 $2; do for y in $3 $4; do for z in $5 $6; do echo "v $x $y $z"; done; done; done
    b=$7
    echo "f $b $((b + 1)) $((b + 3)) $((b + 2))"; echo "f $((b + 4)) $((b + 6)) $((b + 7)) $((b + 5))"
    echo "f $b $((b + 4)) $((b + 5)) $((b + 1))"; echo "f $((b + 2)) $((b + 3)) $((b + 7)) $((b + 6))"
    echo "f $b $((b + 2)) $((b + 6)) $((b + 4))"; echo "f $((b + 1)) $((b + 5)) $((b + 7)) $((b + 3))"
}
{ box -3 3 -2 2 -5.1 -5 1; box -0.5 0.5 -0.5 0.5 -4.72 -4.7 9; } >"$T/plate.obj"
echo '{"width": 64, "height": 48, "fov_y_deg": 55, "near": 0.05, "far": 100,
 "world_to_camera": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}' >"$T/plate.camera.json"
if "$OBSCURA" gbuffer "$T/plate.obj" --camera "$T/plate.camera.json" --deep -o "$T/plate.exr" -q 2>"$T/err"; then
    "$OBSCURA" ao "$T/plate.exr" --method gtao --radius 0.5 -o "$T/g.exr" 2>"$T/err"
    check "deep gtao, deep_intervals auto: the exact integral's 32 steps" "grep -q 'gtao 3 slices x 32 steps' '$T/err'"
    "$OBSCURA" ao "$T/plate.exr" --method gtao --radius 0.5 --gtao-steps 5 -o "$T/g5.exr" 2>"$T/err"
    check "an explicit --gtao-steps wins" "grep -q 'gtao 3 slices x 5 steps' '$T/err'"
    "$OBSCURA" ao "$T/plate.exr" --method gtao --radius 0.5 --deep-intervals off -o "$T/g0.exr" 2>"$T/err"
    check "--deep-intervals off: XeGTAO's defaults" "grep -q 'gtao 3 slices x 3 steps' '$T/err'"
    "$OBSCURA" ao "$T/plate.exr" --method gtao --radius 0.5 -o "$T/gr.exr" --server "unix:$SOCK" -q 2>/dev/null
    check "the daemon resolves the same defaults: same bytes" "cmp -s '$T/g.exr' '$T/gr.exr' && ! cmp -s '$T/g.exr' '$T/g0.exr'"
else
    skip "gbuffer --deep: $(tail -n 1 "$T/err")"
fi

kill -TERM "$PID"
k=0
while [ $k -lt 100 ] && kill -0 "$PID" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
wait "$PID"; rc=$?
PID=""
check "SIGTERM: exit $rc (0)" "[ $rc -eq 0 ]"
[ $failed -ne 0 ] && tail -20 "$T/d.log" | sed 's/^/       /'
echo "e2e deep: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
