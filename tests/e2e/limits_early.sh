#!/bin/sh
# obscurad's early answers to a client that is still sending its body: a
# refusal decided from the headers (a bad parameter, 415, 401, 503) is
# held until the body has arrived, the body discarded, so that the client
# reads the answer instead of a connection reset.  curl sends
# `Expect: 100-continue` only above 1 MiB; `-H 'Expect:'` turns it off
# here, so that every body is on its way when the answer is decided.
#
#   OBSCURAD=build/obscurad tests/e2e/limits_early.sh
#
# Every daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURAD=${OBSCURAD:-build/obscurad}
. tests/e2e/lib/common.sh

echo "e2e early answers: $OBSCURAD"
head -c 900000 /dev/urandom > "$T/body"
# early PORT QUERY N TYPE [curl args]: N posts of the body as TYPE,
# without Expect; prints the statuses seen, each with its count
early() {
    p=$1 q=$2 n=$3 ty=$4; shift 4
    rm -f "$T"/early.*
    i=0
    while [ $i -lt "$n" ]; do
        $CURL -o "$T/early.$i" -w '%{http_code}\n' -H 'Expect:' -H "Content-Type: $ty" \
            --data-binary @"$T/body" "$@" "http://127.0.0.1:$p/v1/ao?$q"
        i=$((i + 1))
    done | sort | uniq -c | awk '{printf "%s%sx%s", (NR > 1 ? " " : ""), $1, $2}'
}
# every answer of the last `early` carries the JSON error CODE
all_errors() { for f in "$T"/early.*; do error_is "$f" "$1" || return 1; done; }

echo "s3cret-token" > "$T/token"
AUTH="Authorization: Bearer s3cret-token"
start E --token-file "$T/token"
out=$(early "$PORT_E" "fov_y=50&radius=abc" 20 image/x-exr -H "$AUTH")
check "20 posts of 900 KB with radius=abc: 400 bad_parameter every time ($out)" \
    "[ '$out' = '20x400' ] && all_errors bad_parameter"
# the same with a client whose socket buffer is small (16 KB): it is still
# sending when the answer is decided, whatever the machine's load (an
# answer queued at once closes the connection, and the client's next
# send meets the reset: it never reads the answer)
out=$(python3 - "$PORT_E" <<'PY'
import socket, sys
port, out = int(sys.argv[1]), []
for _ in range(5):
    s = socket.socket()
    s.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 16384)
    s.settimeout(10)
    s.connect(("127.0.0.1", port))
    body = b"\0" * 900000
    try:
        s.sendall(b"POST /v1/ao?radius=abc HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer s3cret-token\r\n"
                  b"Content-Type: image/x-exr\r\nContent-Length: %d\r\n\r\n" % len(body) + body)
        data = b""
        while b"\r\n\r\n" not in data:
            c = s.recv(65536)
            if not c:
                break
            data += c
        out.append(data.split(b" ", 2)[1].decode() if data.startswith(b"HTTP/1.") else "none")
    except OSError as e:
        out.append(type(e).__name__)
    s.close()
print(" ".join(out))
PY
)
check "5 posts of 900 KB through a 16 KB send buffer with radius=abc: the client sends it all and reads 400 ($out)" \
    "[ '$out' = '400 400 400 400 400' ]"
out=$(early "$PORT_E" "fov_y=50" 5 text/plain -H "$AUTH")
check "5 posts of 900 KB as text/plain: 415 every time ($out)" \
    "[ '$out' = '5x415' ] && all_errors unsupported_media_type"
out=$(early "$PORT_E" "fov_y=50" 5 image/x-exr)
check "5 posts of 900 KB without the token: 401 every time ($out)" "[ '$out' = '5x401' ] && all_errors unauthorized"
code=$($CURL -o "$T/g" -w '%{http_code}' -H 'Expect:' --data-binary @"$T/body" "http://127.0.0.1:$PORT_E/healthz")
check "a 900 KB body sent to GET-only /healthz: 405 read ($code)" "[ '$code' = 405 ] && error_is '$T/g' method_not_allowed"
# the held answer comes at the body's end: the connection stays open for the next request
out=$($CURL -o /dev/null -w '%{http_code} %{num_connects}' -H 'Expect:' -H "$AUTH" --data-binary @"$T/body" \
    "http://127.0.0.1:$PORT_E/v1/ao?radius=abc" --next -o /dev/null -w ' %{http_code} %{num_connects}' \
    "http://127.0.0.1:$PORT_E/healthz")
check "after a held 400 the connection is kept for the next request ($out)" "[ '$out' = '400 1 200 0' ]"
t0=$(date +%s%N)
code=$($CURL -o "$T/x" -w '%{http_code}' -H 'Expect: 100-continue' -H "$AUTH" -H 'Content-Type: image/x-exr' \
    --data-binary @"$T/body" "http://127.0.0.1:$PORT_E/v1/ao?radius=abc")
ms=$(( ($(date +%s%N) - t0) / 1000000 ))
check "with Expect: 100-continue the 400 comes at once, the body unsent ($code in $ms ms)" \
    "[ '$code' = 400 ] && [ $ms -lt 900 ] && error_is '$T/x' bad_parameter"
sleep 0.2
check "the log counts the discarded body of a held answer" "grep -q 'status=400 in=900000 ' '$T/E.log'"

# the queue full: one frame on the GL worker, one waiting (--queue 1)
UPSCALE=${UPSCALE:-$(dirname "$OBSCURAD")/exr_upscale}
if "$UPSCALE" tests/data/room_small.exr 1920x1080 "$T/hd.exr" 2>"$T/up.err"; then
    start Q --queue 1 --max-cost 0 --frame-deadline 0
    slow="fov_y=50&method=hbao&hbao_directions=16&hbao_steps=16"
    post "$PORT_Q" "$slow" "$T/hd.exr" "$T/q1" >/dev/null &
    CPIDS="$!"
    i=0
    while [ $i -lt 100 ] && [ "$($CURL "http://127.0.0.1:$PORT_Q/metrics" | sed -n 's/^obscurad_gl_busy \([0-9]*\)$/\1/p')" != 1 ]; do
        sleep 0.1; i=$((i + 1)); done
    post "$PORT_Q" "$slow" "$T/hd.exr" "$T/q2" >/dev/null &
    CPIDS="$CPIDS $!"
    i=0
    while [ $i -lt 100 ] && [ "$($CURL "http://127.0.0.1:$PORT_Q/metrics" | sed -n 's/^obscurad_queue_depth \([0-9]*\)$/\1/p')" != 1 ]; do
        sleep 0.1; i=$((i + 1)); done
    out=$(early "$PORT_Q" "fov_y=50" 5 image/x-exr)
    check "5 posts of 900 KB with the queue full: 503 queue_full every time ($out)" \
        "[ '$out' = '5x503' ] && all_errors queue_full"
    kill $CPIDS 2>/dev/null
else
    bad "exr_upscale 1920x1080: $(cat "$T/up.err")"
fi

# the body over the limit is answered at once (the client is told before sending it all)
start L --max-body 64k
code=$($CURL -o "$T/l" -w '%{http_code}' -H 'Expect:' -H 'Content-Type: image/x-exr' --data-binary @"$T/body" \
    "http://127.0.0.1:$PORT_L/v1/ao?fov_y=50")
check "a 900 KB body over --max-body 64k: 413, or the reset of a body left unread ($code)" "[ '$code' = 413 ] || [ '$code' = 000 ]"

echo "e2e early answers: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
