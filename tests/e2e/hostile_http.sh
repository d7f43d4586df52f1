#!/bin/sh
# obscurad's HTTP side under hostile and slow clients: a body trickled
# byte by byte (the whole-request deadline, and SIGTERM with such a client
# open), connections made during the drain, many slow connections against
# /healthz, the per-client limit, log injection and NUL in query values,
# framing headers that disagree, IPv6 listeners and keep-alive.
#
#   OBSCURAD=build/obscurad tests/e2e/hostile_http.sh
#
# Loopback only (127.0.0.0/8 source addresses, ::1); every wait is bounded.
set -u
OBSCURAD=${OBSCURAD:-build/obscurad}
. tests/e2e/lib/common.sh
PY="python3 tests/e2e/lib/httpclient.py"
R=tests/data/room_small.exr

if ! command -v python3 >/dev/null 2>&1 || ! command -v curl >/dev/null 2>&1; then
    echo "hostile_http e2e: python3 or curl not found"; exit 1
fi
# 1 when $1 (seconds, a decimal) is below $2
below() { awk "BEGIN { exit !($1 < $2) }"; }
# 0 while pid $1 runs (a zombie, not yet reaped, has ended)
running() { s=$(ps -o stat= -p "$1" 2>/dev/null) && [ "${s#Z}" = "$s" ]; }
# waits up to $2 tenths of a second for pid $1 to end; prints the tenths taken
wait_exit() {
    k=0
    while [ $k -lt "$2" ] && running "$1"; do sleep 0.1; k=$((k + 1)); done
    echo $k
}

echo "e2e hostile HTTP: $OBSCURAD"

echo "-- keep-alive"
start K
out=$($PY keepalive "$PORT_K" 5)
check "five GET /healthz on one connection, no Connection: close ($out)" "[ '$out' = 'answered 5 close-header 0' ]"
code=$($CURL -o "$T/ka" -w '%{http_code} %{num_connects}' -H 'Content-Type: image/x-exr' \
    --data-binary @"$R" "http://127.0.0.1:$PORT_K/v1/ao?fov_y=50" \
    --next -o "$T/ka2" -w ' %{http_code} %{num_connects}' -H 'Content-Type: image/x-exr' --data-binary @"$R" "http://127.0.0.1:$PORT_K/v1/ao?fov_y=50")
check "two POST /v1/ao through curl --next share one connection ($code)" "[ '$code' = '200 1 200 0' ]"

echo "-- framing headers that disagree: 400 at once"
out=$($PY raw "$PORT_K" 'POST /v1/ao HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n' 5)
check "Content-Length and Transfer-Encoding: 400 ($out)" "[ \"\${out%% *}\" = 400 ] && below \${out#* } 2"
out=$($PY raw "$PORT_K" 'POST /v1/ao HTTP/1.1\r\nHost: x\r\nContent-Length: 3\r\nContent-Length: 5\r\n\r\nabc' 5)
check "two different Content-Lengths: 400 ($out)" "[ \"\${out%% *}\" = 400 ] && below \${out#* } 2"
out=$($PY raw "$PORT_K" 'POST /v1/ao HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: gzip\r\n\r\nabc' 5)
check "unknown transfer coding: 400 at once ($out)" "[ \"\${out%% *}\" = 400 ] && below \${out#* } 2"
out=$($PY raw "$PORT_K" 'GET /healthz HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\nContent-Length: 0\r\n\r\n' 5)
check "the same Content-Length twice is one: 200 ($out)" "[ \"\${out%% *}\" = 200 ]"

echo "-- NUL and control characters in query values; the log"
code=$(post "$PORT_K" "fov_y=50&radius=0.5%00x" "$R" "$T/e")
check "radius=0.5%00x: 400 naming radius" "[ $code = 400 ] && error_is $T/e bad_parameter && grep -q radius $T/e"
code=$(post "$PORT_K" "fov_y=50&depth=Z%00junk" "$R" "$T/e")
check "depth=Z%00junk: 400 naming depth" "[ $code = 400 ] && grep -q depth $T/e"
code=$(post "$PORT_K" "fov_y=50&depth=Z%0A2030-01-01T00:00:00.000Z%20obscurad%20info:%20FORGED" "$R" "$T/e")
get "$PORT_K" "/nope%0AFORGED2" "$T/e2" >/dev/null
sleep 0.3
check "a %0A in a value or a path forges no log line" "! grep -q '^2030-01-01\\|^FORGED' $T/K.log && grep -q 'FORGED' $T/K.log"
code=$(post "$PORT_K" "fov_y=50&%FF%FEbad=1" "$R" "$T/e")
check "an unknown name with invalid UTF-8: 400, the JSON is valid UTF-8" \
    "[ $code = 400 ] && python3 -c 'import json,sys; json.loads(open(sys.argv[1],\"rb\").read().decode(\"utf-8\"))' $T/e"

echo "-- per-client limit"
start P --max-per-client 8
out=$($PY perclient "$PORT_P" 8)
check "a 9th connection from one address is answered (its /healthz, a probe, still 200), another address too ($out)" \
    "echo '$out' | grep -q 'same 200/' && echo '$out' | grep -q 'other 200/'"

echo "-- 1,100 slow connections and /healthz"
start S
out=$($PY slow "$PORT_S" 1100 40)
ms=$(echo "$out" | sed -n 's/.*healthz 200 \([0-9]*\)$/\1/p')
check "/healthz answers within 2 s with 1,100 slow connections open ($out)" "[ -n '$ms' ] && [ '$ms' -lt 2000 ]"
check "/healthz answers with the slow connections closed" "[ \$(get $PORT_S /healthz $T/g) = 200 ]"

echo "-- whole-request deadline"
start D --request-timeout 3 --timeout 30
out=$($PY trickle "$PORT_D" 0.5 20)
check "a body trickled byte by byte ends at --request-timeout 3 ($out)" \
    "case '$out' in 408\\ *|closed\\ *) below \${out#* } 6;; *) false;; esac"
out=$($PY raw "$PORT_D" 'GET /healthz HTTP/1.1\r\nHost: x\r\nX-Slow: a' 10)
check "headers never finished: closed by the deadline ($out)" "below \${out#* } 6"
check "the daemon still answers" "[ \$(get $PORT_D /healthz $T/g) = 200 ]"

echo "-- SIGTERM with a trickling client; connections during the drain"
start T1 --request-timeout 5 --timeout 30
$PY trickle "$PORT_T1" 0.5 40 >"$T/trickle.out" &
CPIDS="$!"
sleep 1
kill -TERM "$PID_T1"
sleep 0.5
out=$($PY connect "$PORT_T1" 5)
check "a connection made during the drain is refused or answered at once ($out)" \
    "case '$out' in refused\\ *) true;; 503\\ *|200\\ *) below \${out#* } 1;; *) false;; esac"
k=$(wait_exit "$PID_T1" 150)
check "SIGTERM exits with a trickling client open (in $k tenths of a second)" "! running $PID_T1"

echo "-- IPv6"
if [ -r /proc/net/if_inet6 ] && grep -q '^0\{31\}1 ' /proc/net/if_inet6; then
    : > "$T/v6.log"
    "$OBSCURAD" --http '[::1]:0' 2>"$T/v6.log" &
    V6=$!
    PIDS="$PIDS $V6"
    i=0 p6=""
    while [ $i -lt 300 ] && [ -z "$p6" ]; do
        p6=$(sed -n 's/.*listening on http:\/\/\[::1\]:\([0-9]*\).*/\1/p' "$T/v6.log")
        kill -0 $V6 2>/dev/null || break
        [ -z "$p6" ] && sleep 0.1
        i=$((i + 1))
    done
    check "--http [::1]:0 logs listening on http://[::1]:PORT" "[ -n '$p6' ]"
    check "GET http://[::1]:PORT/healthz 200" "[ \$($CURL -g -o $T/g -w '%{http_code}' 'http://[::1]:$p6/healthz') = 200 ]"
    "$OBSCURAD" --http '[::]:0' 2>"$T/v6b.log" &
    V6B=$!
    PIDS="$PIDS $V6B"
    i=0 p6=""
    while [ $i -lt 300 ] && [ -z "$p6" ]; do
        p6=$(sed -n 's/.*listening on http:\/\/\[::\]:\([0-9]*\).*/\1/p' "$T/v6b.log")
        kill -0 $V6B 2>/dev/null || break
        [ -z "$p6" ] && sleep 0.1
        i=$((i + 1))
    done
    check "--http [::]:0 listens, answers on ::1" "[ -n '$p6' ] && [ \$($CURL -g -o $T/g -w '%{http_code}' 'http://[::1]:$p6/healthz') = 200 ]"
    "$OBSCURAD" --http '[::1:0' >"$T/v6c.log" 2>&1
    check "--http '[::1:0' refused" "[ $? -ne 0 ] && grep -q 'is not' $T/v6c.log"
else
    echo "  skip IPv6: no ::1 on this host"
fi

if [ $failed -ne 0 ]; then
    for n in K P S D T1; do [ -f "$T/$n.log" ] && { echo "  --- log $n (tail)"; tail -5 "$T/$n.log" | sed 's/^/       /'; }; done
fi
echo "e2e hostile_http: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
