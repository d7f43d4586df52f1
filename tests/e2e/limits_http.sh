#!/bin/sh
# obscurad's HTTP limits seen from a client: --cors (preflights answered,
# Access-Control-Allow-Origin on answers; off by default), a connection
# over --max-per-client answered 503 too_many_connections that the client
# can read (even while it sends a body), every refusal counted in
# /metrics by reason and logged at most once a second per reason, and the
# event subscribers' gauge dropping when a client leaves.
#
#   OBSCURAD=build/obscurad tests/e2e/limits_http.sh
#
# Loopback only (127.0.9.x source addresses); every wait is bounded.
set -u
OBSCURAD=${OBSCURAD:-build/obscurad}
. tests/e2e/lib/common.sh
R=tests/data/room_small.exr

echo "e2e HTTP limits: $OBSCURAD"

echo "-- --cors"
start O
code=$($CURL -o "$T/o0" -D "$T/o0.h" -w '%{http_code}' -X OPTIONS "http://127.0.0.1:$PORT_O/v1/ao")
check "without --cors: OPTIONS /v1/ao is 405, no Access-Control header ($code)" \
    "[ '$code' = 405 ] && ! grep -qi '^Access-Control' '$T/o0.h'"
echo "s3cret-token" > "$T/token"
AUTH="Authorization: Bearer s3cret-token"
start C --cors https://preview.example.com --token-file "$T/token"
PRE="-H Origin:https://preview.example.com -H Access-Control-Request-Method:POST -H Access-Control-Request-Headers:content-type"
for path in /v1/ao /v1/info /healthz /v1/streams/s/frames /v1/bakes; do
    code=$($CURL -o /dev/null -D "$T/c.h" -w '%{http_code}' -X OPTIONS $PRE "http://127.0.0.1:$PORT_C$path")
    check "--cors: OPTIONS $path (no token) is 204 with the Allow-Origin, -Methods, -Headers and -Max-Age ($code)" \
        "[ '$code' = 204 ] && grep -qi '^Access-Control-Allow-Origin: https://preview.example.com' '$T/c.h' && \
         grep -qi '^Access-Control-Allow-Methods: ' '$T/c.h' && grep -qi '^Access-Control-Allow-Headers: .*Content-Type' '$T/c.h' && \
         grep -qi '^Access-Control-Max-Age: ' '$T/c.h'"
done
code=$(post "$PORT_C" "fov_y=50" "$R" "$T/c1" -H 'Origin: https://preview.example.com')
check "--cors: an error answer (401, no token) carries Access-Control-Allow-Origin ($code)" \
    "[ '$code' = 401 ] && grep -qi '^Access-Control-Allow-Origin: https://preview.example.com' '$T/c1.h'"
code=$(post "$PORT_C" "fov_y=50" "$R" "$T/c2" -H 'Origin: https://preview.example.com' -H "$AUTH")
check "--cors: a frame's answer too, exposing X-Obscura-Warning and Server-Timing ($code)" \
    "[ '$code' = 200 ] && grep -qi '^Access-Control-Allow-Origin: https://preview.example.com' '$T/c2.h' && \
     grep -qi '^Access-Control-Expose-Headers: .*X-Obscura-Warning.*Server-Timing' '$T/c2.h'"

echo "-- --max-per-client"
# held PORT N PATH BODY: N connections from 127.0.9.1 each inside a
# request (headers unfinished), then one more from there asking PATH
# (with BODY bytes sent at once, no Expect), one from 127.0.9.2: prints
# 'same STATUS other STATUS' and the answer's body into $T/pc.json
held() {
    python3 - "$@" "$T/pc.json" <<'PY'
import socket, sys, time
port, n, path, body, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], int(sys.argv[4]), sys.argv[5]
socks = []
for _ in range(n):
    s = socket.create_connection(("127.0.0.1", port), 5, ("127.0.9.1", 0))
    s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
    socks.append(s)
time.sleep(0.3)
def ask(src):
    try:
        s = socket.create_connection(("127.0.0.1", port), 5, (src, 0))
    except OSError:
        return "refused", b""
    head = "%s %s HTTP/1.1\r\nHost: x\r\n" % ("POST" if body else "GET", path)
    if body:
        head += "Content-Type: image/x-exr\r\nContent-Length: %d\r\n" % body
    try:
        s.sendall(head.encode() + b"\r\n" + b"\0" * body)
    except OSError:
        pass
    data = b""
    try:
        while True:
            c = s.recv(65536)
            if not c:
                break
            data += c
    except OSError as e:
        if not data:
            return "reset", b""
    st = data.split(b" ", 2)[1].decode() if data.startswith(b"HTTP/1.") else "none"
    return st, data.split(b"\r\n\r\n", 1)[-1]
same, sbody = ask("127.0.9.1")
other, _ = ask("127.0.9.2")
open(out, "wb").write(sbody)
print("same %s other %s" % (same, other))
PY
}
start P --max-per-client 8
out=$(held "$PORT_P" 8 /v1/info 0)
check "a 9th connection from one address asking GET /v1/info: 503 too_many_connections naming --max-per-client ($out)" \
    "[ '$out' = 'same 503 other 200' ] && error_is '$T/pc.json' too_many_connections && grep -q 'max-per-client 8' '$T/pc.json'"
out=$(held "$PORT_P" 8 /v1/ao 900000)
check "the 9th posting 900 KB without waiting reads its 503 too, not a reset ($out)" \
    "[ '$out' = 'same 503 other 422' ] && error_is '$T/pc.json' too_many_connections"
out=$(held "$PORT_P" 8 /healthz 0)
check "/healthz on the 9th connection is still answered (a probe costs nothing) ($out)" "[ '$out' = 'same 200 other 200' ]"
sleep 0.3
check "the refusal is in the log, naming the option" "grep -q 'status=503.*too_many_connections.*max-per-client' '$T/P.log'"

echo "-- --max-per-client over the binary protocol"
# one connection holds the Unix socket's only place; the CLI then writes
# a whole frame (more than the socket's buffer) before it reads: it must
# read the 503, which the daemon sends, then drains the frame for a while
OBSCURA=${OBSCURA:-$(dirname "$OBSCURAD")/obscura}
start B --socket "$T/b.sock" --max-per-client 1
python3 -u -c 'import socket, sys, time
s = socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); print("held"); time.sleep(20)' "$T/b.sock" > "$T/hold" &
HOLD=$!
CPIDS="$HOLD"
i=0
while [ $i -lt 100 ] && ! grep -q held "$T/hold"; do sleep 0.1; i=$((i + 1)); done
sleep 0.2
"$OBSCURA" ao "$R" --camera tests/data/room_small.camera.json -o "$T/b.exr" --server "unix:$T/b.sock" -q 2>"$T/b.err"
rc=$?
check "the frame over --max-per-client reads 503 too_many_connections, not EOF (exit $rc: $(head -c 160 "$T/b.err"))" \
    "[ $rc -ne 0 ] && grep -q 'too_many_connections\|too many connections' '$T/b.err'"
n=$($CURL "http://127.0.0.1:$PORT_B/metrics" | sed -n 's/^obscurad_refusals_total{reason="too_many_connections"} \([0-9]*\)$/\1/p')
check "the binary refusals are counted in obscurad_refusals_total ($n)" "[ -n '$n' ] && [ '$n' -ge 1 ]"
kill "$HOLD" 2>/dev/null

echo "-- refusals in /metrics"
$CURL "http://127.0.0.1:$PORT_P/metrics" > "$T/p.metrics"
n=$(sed -n 's/^obscurad_refusals_total{reason="too_many_connections"} \([0-9]*\)$/\1/p' "$T/p.metrics")
check "obscurad_refusals_total{reason=\"too_many_connections\"} counts the two refusals ($n)" "[ '$n' = 2 ]"
lines=$(grep -c 'warn: refused too_many_connections' "$T/P.log")
check "the refusals are logged, rate-limited to a line a second ($lines lines)" "[ '$lines' -ge 1 ] && [ '$lines' -le 2 ]"
i=0
while [ $i -lt 10 ]; do
    $CURL -o /dev/null -H 'Content-Type: image/x-exr' -H 'Content-Length: 99999999999' -X POST \
        "http://127.0.0.1:$PORT_P/v1/ao?fov_y=50"
    i=$((i + 1))
done
sleep 1.1
$CURL -o /dev/null -H 'Content-Type: image/x-exr' -H 'Content-Length: 99999999999' -X POST "http://127.0.0.1:$PORT_P/v1/ao"
sleep 0.2
n=$($CURL "http://127.0.0.1:$PORT_P/metrics" | sed -n 's/^obscurad_refusals_total{reason="body_too_large"} \([0-9]*\)$/\1/p')
lines=$(grep -c 'warn: refused body_too_large' "$T/P.log")
check "11 bodies over --max-body: 11 counted, at most a log line a second, the next says how many it left out ($n, $lines lines)" \
    "[ '$n' = 11 ] && [ '$lines' -lt 11 ] && grep -q 'warn: refused body_too_large.*more since the last such line' '$T/P.log'"

echo "-- the event subscribers' gauge"
metric() { $CURL "http://127.0.0.1:$1/metrics" | sed -n "s/^$2 \([0-9]*\)$/\1/p"; }
start V
curl -s -N --max-time 30 "http://127.0.0.1:$PORT_V/v1/streams/s/events" > "$T/ev" &
EV=$!
CPIDS="$EV"
i=0
while [ $i -lt 50 ] && [ "$(metric "$PORT_V" obscurad_event_subscribers)" != 1 ]; do sleep 0.1; i=$((i + 1)); done
g1=$(metric "$PORT_V" obscurad_event_subscribers)
kill "$EV"
t0=$(date +%s%N)
i=0
while [ $i -lt 30 ] && [ "$(metric "$PORT_V" obscurad_event_subscribers)" != 0 ]; do sleep 0.05; i=$((i + 1)); done
ms=$(( ($(date +%s%N) - t0) / 1000000 ))
g0=$(metric "$PORT_V" obscurad_event_subscribers)
check "a subscriber that leaves is dropped from obscurad_event_subscribers within a second ($g1 -> $g0 in $ms ms)" \
    "[ '$g1' = 1 ] && [ '$g0' = 0 ] && [ $ms -lt 1200 ]"

echo "e2e HTTP limits: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
