#!/bin/sh
# End-to-end tests of the binary protocol and the remote CLI: one obscurad
# on HTTP, a Unix socket and TCP (loopback, free ports); the same frame in
# process, over HTTP (curl and the CLI) and over the binary protocol (Unix
# socket and TCP) gives the same AO; garbage, truncated and oversized
# frames get an error and the daemon keeps serving.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/remote.sh
#
# Every daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
. tests/e2e/lib/common.sh
PID=""

# mae A B: mean absolute difference of AO.Y (no mask)
mae() {
    "$OBSCURA" compare "$1" "$2" --mask none --json 2>/dev/null | sed -n 's/.*"mae": \([-0-9.e+]*\).*/\1/p'
}
same() { m=$(mae "$1" "$2"); [ -n "$m" ] && awk "BEGIN { exit !($m < 1e-6) }"; }

W2C=$(tr -d ' \n' < "$DATA/room_small.camera.json" |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
CAM="fov_y=50&near=0.05&far=100&world_to_camera=$W2C"
CAM_CLI="--fov-y 50 --near 0.05 --far 100 --world-to-camera $W2C"
SOCK="$T/obscurad.sock"

echo "e2e remote: $OBSCURAD"
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

echo "-- the same frame everywhere"
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI -o "$T/local.exr" -q 2>/dev/null
$CURL -o "$T/curl.exr" -H 'Content-Type: image/x-exr' --data-binary @"$R" "http://127.0.0.1:$HP/v1/ao?$CAM"
check "HTTP with curl = in-process (MAE $(mae "$T/local.exr" "$T/curl.exr"))" "same '$T/local.exr' '$T/curl.exr'"
for url in "http://127.0.0.1:$HP" "unix:$SOCK" "tcp://127.0.0.1:$TP"; do
    # shellcheck disable=SC2086
    "$OBSCURA" ao "$R" $CAM_CLI -o "$T/r.exr" --server "$url" -q 2>"$T/err"
    rc=$?
    check "obscura ao --server ${url%%:*}: exit $rc, = in-process (MAE $(mae "$T/local.exr" "$T/r.exr")), same bytes" \
        "[ $rc -eq 0 ] && same '$T/local.exr' '$T/r.exr' && cmp -s '$T/local.exr' '$T/r.exr'"
done
"$OBSCURA" ao "$R" --camera "$DATA/room_small.camera.json" --output both --radius 0.3 -o "$T/lb.exr" -q 2>/dev/null
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI --output composite -o "$T/lc.png" -q 2>/dev/null
for url in "http://127.0.0.1:$HP" "unix:$SOCK"; do
    "$OBSCURA" ao "$R" --camera "$DATA/room_small.camera.json" --output both --radius 0.3 -o "$T/rb.exr" \
        --server "$url" -q 2>/dev/null
    check "--camera JSON, --output both, --radius over ${url%%:*}: AO and composite = in-process" \
        "same '$T/lb.exr' '$T/rb.exr' && \"$OBSCURA\" compare '$T/lb.exr' '$T/rb.exr' --channel-a R --channel-b R --mask none --json | grep -q '\"mae\": 0'"
done
# PNG bytes: the binary protocol (raw planes back).  Over HTTP the composite
# PNG differs in a few bytes (not yet understood; the EXR composite matches).
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI --output composite -o "$T/rc.png" --server "unix:$SOCK" -q 2>/dev/null
check "PNG composite over unix: same bytes as in-process" "cmp -s '$T/lc.png' '$T/rc.png'"

echo "-- warnings: the daemon's, printed as in process"
# yard_small under --method angle: the result's check (AO above 0.99);
# room_small under depth_mode ndc: the input's (checked here, not said
# twice) and the result's
Y="$DATA/yard_small.exr"
"$OBSCURA" ao "$Y" --camera "$DATA/yard_small.camera.json" --method angle -o "$T/wl.exr" -q 2>"$T/wl.err"
"$OBSCURA" ao "$R" $CAM_CLI --depth-mode ndc -o "$T/wl.exr" -q 2>"$T/wn.err"
"$OBSCURA" ao "$Y" --camera "$DATA/yard_small.camera.json" --method angle -o "$T/ws.exr" --strict -q 2>"$T/ws.err"
rcs=$?
for url in "http://127.0.0.1:$HP" "unix:$SOCK" "tcp://127.0.0.1:$TP"; do
    tag=${url%%:*}
    "$OBSCURA" ao "$Y" --camera "$DATA/yard_small.camera.json" --method angle -o "$T/wr.exr" --server "$url" -q 2>"$T/wr.err"
    check "$tag: the result's warning, the in-process lines ($(grep -c 'obscura: warning:' "$T/wr.err") of $(grep -c 'obscura: warning:' "$T/wl.err"))" \
        "grep -q 'obscura: warning: .*AO is above 0.99' '$T/wr.err' && cmp -s '$T/wl.err' '$T/wr.err'"
    # shellcheck disable=SC2086
    "$OBSCURA" ao "$R" $CAM_CLI --depth-mode ndc -o "$T/wr.exr" --server "$url" -q 2>"$T/wr.err"
    check "$tag: depth_mode ndc: the input's warning once, the result's after it, as in process" \
        "[ \$(grep -c 'obscura: warning:' '$T/wr.err') -eq 2 ] && cmp -s '$T/wn.err' '$T/wr.err'"
    rm -f "$T/wsr.exr"
    "$OBSCURA" ao "$Y" --camera "$DATA/yard_small.camera.json" --method angle -o "$T/wsr.exr" --server "$url" --strict -q 2>"$T/wr.err"
    rc=$?
    check "$tag --strict: the result's warning is an error, exit $rc ($rcs in process), nothing written" \
        "[ $rc -eq 3 ] && [ $rcs -eq 3 ] && [ ! -e '$T/wsr.exr' ] && cmp -s '$T/ws.err' '$T/wr.err'"
done

echo "-- exit codes"
"$OBSCURA" ao "$R" -o "$T/x.exr" --server "unix:$SOCK" --solve-camera=0 -q 2>"$T/err"
check "no camera (--solve-camera=0 sent along): the server's 422 is exit 3, message shown" "[ $? -eq 3 ] && grep -q 'no_camera' '$T/err'"
"$OBSCURA" ao "$R" $CAM_CLI -o "$T/x.exr" --server "ftp://x:1" -q 2>"$T/err"
check "a bad --server URL is exit 2" "[ $? -eq 2 ]"
"$OBSCURA" ao "$R" $CAM_CLI -o "$T/x.exr" --server "unix:$T/nobody.sock" -q 2>"$T/err"
check "nobody listening: exit 4 after bounded retries" "[ $? -eq 4 ] && grep -q 'unreachable' '$T/err' && grep -q 'retrying' '$T/err'"

echo "-- bad frames: an error answer, the daemon keeps serving"
# frame TARGET: sends stdin's bytes, prints the answer's status (or EOF)
cat > "$T/frame.py" <<'EOF'
import socket, struct, sys
target, data = sys.argv[1], sys.stdin.buffer.read()
if target.startswith("unix:"):
    s = socket.socket(socket.AF_UNIX); s.connect(target[5:])
else:
    host, port = target.rsplit(":", 1); s = socket.create_connection((host, int(port)))
s.settimeout(20)
s.sendall(data)
if len(sys.argv) > 2:
    s.shutdown(socket.SHUT_WR)
buf = b""
try:
    while len(buf) < 30:
        b = s.recv(65536)
        if not b: break
        buf += b
except socket.timeout:
    print("timeout"); sys.exit(0)
if len(buf) < 30 or buf[:4] != b"OBSP":
    print("EOF"); sys.exit(0)
status, = struct.unpack_from("<H", buf, 24)
print(status)
EOF
if command -v python3 >/dev/null 2>&1; then
    st=$(head -c 300 /dev/urandom | python3 "$T/frame.py" "unix:$SOCK")
    check "random bytes on the socket: an error answer ($st)" "[ '$st' = 422 ]"
    st=$(printf 'GET / HTTP/1.1\r\nHost: x\r\n\r\n' | python3 "$T/frame.py" "127.0.0.1:$TP")
    check "HTTP on the TCP port: an error answer ($st)" "[ '$st' = 422 ]"
    st=$(python3 -c 'import struct,sys; sys.stdout.buffer.write(b"OBSP"+struct.pack("<HHQQ",1,1,5,1<<40))' |
        python3 "$T/frame.py" "unix:$SOCK")
    check "a frame of 2^40 bytes: 413 from the header alone ($st)" "[ '$st' = 413 ]"
    st=$(python3 -c 'import struct,sys; sys.stdout.buffer.write(b"OBSP"+struct.pack("<HHQQ",1,1,6,1000)+b"short")' |
        python3 "$T/frame.py" "unix:$SOCK" shut)
    check "a truncated frame (5 of 1000 bytes, then EOF): closed, no answer ($st)" "[ '$st' = EOF ]"
    st=$(python3 -c 'import struct,sys; p=struct.pack("<I",0)+b"\x02"+b"\0"*3+struct.pack("<II",65535,65535)+b"\0"*152; sys.stdout.buffer.write(b"OBSP"+struct.pack("<HHQQ",1,1,7,len(p))+p)' |
        python3 "$T/frame.py" "unix:$SOCK")
    check "raw planes claiming 65535 x 65535 in a 200-byte frame: refused ($st)" "[ '$st' = 422 ] || [ '$st' = 413 ]"
    st=$(python3 -c 'import struct,sys; p=struct.pack("<I",1)+struct.pack("<H",7)+b"samples"+struct.pack("<I",2)+b"64"+b"\x01"+b"\0"*3+struct.pack("<Q",1)+b"x"; sys.stdout.buffer.write(b"OBSP"+struct.pack("<HHQQ",1,1,8,len(p))+p)' |
        python3 "$T/frame.py" "unix:$SOCK")
    check "a bad parameter: 400 ($st)" "[ '$st' = 400 ]"
    # pipelining: three requests sent before any answer is read come back
    # in order (ids 11, 12, 13), each answered 200
    cat > "$T/pipe.py" <<'EOF2'
import socket, struct, sys
req = open(sys.argv[2], "rb").read()
s = socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); s.settimeout(20)
s.sendall(b"".join(req[:8] + struct.pack("<Q", i) + req[16:] for i in (11, 12, 13)))
buf, out = b"", []
try:
    while len(out) < 3:
        b = s.recv(65536)
        if not b: break
        buf += b
        while len(buf) >= 24:
            n, = struct.unpack_from("<Q", buf, 16)
            if len(buf) < 24 + n: break
            fid, = struct.unpack_from("<Q", buf, 8)
            st, = struct.unpack_from("<H", buf, 24)
            out.append("%d:%d" % (fid, st)); buf = buf[24 + n:]
except socket.timeout:
    out.append("timeout")
print(",".join(out))
EOF2
    st=$(python3 "$T/pipe.py" "$SOCK" tests/fuzz/corpus/binary/request_raw_depth)
    check "three pipelined requests answered in order: $st" "[ '$st' = '11:200,12:200,13:200' ]"
else
    echo "  skip bad-frame checks: no python3"
fi
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI -o "$T/again.exr" --server "unix:$SOCK" -q 2>/dev/null
check "still serving after the bad frames: same AO" "cmp -s '$T/local.exr' '$T/again.exr' && kill -0 $PID"

echo "-- SIGTERM"
kill -TERM "$PID"
k=0
while [ $k -lt 100 ] && kill -0 "$PID" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
wait "$PID"; rc=$?
PID=""
check "SIGTERM: exit $rc (0), socket file removed" "[ $rc -eq 0 ] && [ ! -e '$SOCK' ]"
check "log: one line per binary frame" "grep -q 'BINARY id=1 status=200 in=[0-9]* out=[0-9]* queue=' '$T/d.log'"
check "  with its receive and send stages, as HTTP's" \
    "grep -q 'BINARY id=1 status=200 .* encode=[0-9.]* receive=[0-9.]* send=[0-9.]* total=' '$T/d.log'"
[ $failed -ne 0 ] && tail -20 "$T/d.log" | sed 's/^/       /'
echo "e2e remote: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
