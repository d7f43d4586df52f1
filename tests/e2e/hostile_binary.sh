#!/bin/sh
# End-to-end tests of obscurad's binary protocol under hostile and slow
# clients (tests/e2e/lib/binclient.py plays them): a client that never
# reads its answer, one that keeps sending through SIGTERM, frames refused
# from their head (no token, too large, a full queue) before their
# G-buffer is read, more connections than allowed, and IPv6 listeners.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/hostile_binary.sh
#
# Loopback only (127.0.0.1, 127.0.0.2, ::1, Unix sockets); every wait is
# bounded; every daemon it starts is killed on exit.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
. tests/e2e/lib/common.sh
BC="python3 tests/e2e/lib/binclient.py"

echo "e2e hostile_binary: $OBSCURAD"
if ! command -v python3 >/dev/null 2>&1; then
    echo "  skip: no python3"
    echo "e2e hostile_binary: 0 passed, 0 failed"
    exit 0
fi

# bstart NAME TCP ARGS...: obscurad on a Unix socket and TCP address TCP
# (port 0), no HTTP; sets PID_NAME, TP_NAME (the port) and SOCK_NAME.
bstart() {
    name=$1 tcp=$2; shift 2
    : > "$T/$name.log"
    "$OBSCURAD" --http '' --socket "$T/$name.sock" --tcp "$tcp" "$@" 2>"$T/$name.log" &
    pid=$!
    PIDS="$PIDS $pid"
    port=""
    i=0
    while [ $i -lt 300 ] && { [ -z "$port" ] || [ ! -S "$T/$name.sock" ]; }; do
        port=$(sed -n 's/.*binary protocol on tcp:\/\/.*:\([0-9][0-9]*\)$/\1/p' "$T/$name.log")
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
        i=$((i + 1))
    done
    eval "PID_$name=$pid; TP_$name=$port; SOCK_$name=$T/$name.sock"
    if [ -n "$port" ] && [ -S "$T/$name.sock" ]; then ok "$name: obscurad on tcp port $port and unix"; else
        bad "$name: obscurad did not start"; sed 's/^/       /' "$T/$name.log" | tail -3; return 1; fi
}

# stop_wait PID SECONDS: SIGTERM, then waits at most SECONDS (in this
# shell: it reaps the child); sets RC (the exit status, "-" if it did not
# exit: then it is killed) and TENTHS (how long it took)
stop_wait() {
    kill -TERM "$1" 2>/dev/null
    TENTHS=0
    while [ $TENTHS -lt $(($2 * 10)) ] && kill -0 "$1" 2>/dev/null; do sleep 0.1; TENTHS=$((TENTHS + 1)); done
    if kill -0 "$1" 2>/dev/null; then
        kill -KILL "$1" 2>/dev/null; wait "$1" 2>/dev/null; RC=-
    else
        wait "$1"; RC=$?
    fi
}

echo "-- 1: a client that never reads its answer"
if bstart stall 127.0.0.1:0 --timeout 3; then
    $BC stall "127.0.0.1:$TP_stall" 2048 1024 > "$T/stall.out" 2>&1 &
    CPID=$!
    CPIDS="$CPID"
    i=0
    while [ $i -lt 300 ] && ! grep -q stuck "$T/stall.out"; do sleep 0.1; i=$((i + 1)); done
    check "a 2048 x 1024 format=raw answer is on its way, the client reads none of it" "grep -q stuck '$T/stall.out'"
    stop_wait "$PID_stall" 20
    check "SIGTERM: obscurad exits 0 within 20 s (exit $RC after $TENTHS tenths of a second; --timeout 3)" \
        "[ '$RC' = 0 ] && [ $TENTHS -le 100 ]"
    check "log: the send gave up, the client does not read" "grep -q 'the client does not read; gave up' '$T/stall.log'"
    kill -KILL "$CPID" 2>/dev/null; wait "$CPID" 2>/dev/null; CPIDS=""
fi

echo "-- 3: after SIGTERM no new frame starts (with a token)"
printf 'sekrit\n' > "$T/token"
if bstart drain 127.0.0.1:0 --token-file "$T/token"; then
    r=$(timeout 50 $BC pipeline "unix:$SOCK_drain" "$PID_drain" sekrit)
    check "a client sending frames two at a time through SIGTERM: answered shutting_down, then closed ($r)" \
        "echo '$r' | grep -q 'last=503:shutting_down eof=1'"
    stop_wait "$PID_drain" 10
    check "then obscurad exits 0 within 10 s (exit $RC after $TENTHS tenths)" "[ '$RC' = 0 ]"
    n=$(grep -c 'BINARY id=.* status=200' "$T/drain.log")
    check "log: the frames before SIGTERM were answered 200 ($n)" "[ $n -ge 3 ]"
fi

echo "-- 6: nothing of a frame is read before it is allowed"
if bstart auth 127.0.0.1:0 --token-file "$T/token" --max-pixels 1m; then
    r=$(timeout 55 $BC oversized "unix:$SOCK_auth" "$PID_auth" -)
    check "a 200 MB frame without the token: 401 before its planes are read ($r)" \
        "echo '$r' | grep -q 'status=401:unauthorized'"
    g=$(echo "$r" | sed -n 's/.*rss_growth_mb=\([0-9-]*\).*/\1/p')
    check "  and obscurad's peak RSS grew by less than 50 MB (${g:-?} MB)" "[ -n '$g' ] && [ $g -lt 50 ]"
    r=$(timeout 20 $BC headonly "unix:$SOCK_auth" 2048 2048 sekrit)
    check "2048 x 2048 over --max-pixels 1m: 413 from the head, planes never sent, closed ($r)" \
        "[ '$r' = 'answer=413:too_large closed=1' ]"
    r=$(timeout 20 $BC headonly "127.0.0.1:$TP_auth" 16 16 wrong)
    check "a wrong token: 401 from the head, closed ($r)" "[ '$r' = 'answer=401:unauthorized closed=1' ]"
    stop_wait "$PID_auth" 20
    check "SIGTERM: exit 0 ($RC)" "[ '$RC' = 0 ]"
fi
if bstart busy 127.0.0.1:0 --queue 1; then
    r=$(timeout 55 $BC busy "unix:$SOCK_busy" 1024 1024)
    check "the queue full: a frame's head is answered 503 queue_full, its planes unsent ($r)" \
        "[ '$r' = 'probe=503:queue_full' ]"
    stop_wait "$PID_busy" 30
    check "SIGTERM: exit 0 ($RC)" "[ '$RC' = 0 ]"
fi

echo "-- 7: connection limits"
if bstart many 127.0.0.1:0 --max-per-client 0; then
    r=$(timeout 55 $BC conns "127.0.0.1:$TP_many" 300)
    check "300 connections, --bin-connections 256: 256 open, 44 answered 503 too_many_connections and closed ($r)" \
        "[ '$r' = '503:too_many_connections=44 open=256' ]"
    stop_wait "$PID_many" 20
    check "SIGTERM with 256 idle connections: exit 0 within 20 s ($RC, $TENTHS tenths)" "[ '$RC' = 0 ]"
fi
if bstart per 127.0.0.1:0 --max-per-client 4 --bin-connections 16; then
    r=$(timeout 30 $BC conns "127.0.0.1:$TP_per" 6)
    check "--max-per-client 4: 6 from 127.0.0.1 -> 4 open, 2 refused ($r)" \
        "[ '$r' = '503:too_many_connections=2 open=4' ]"
    r=$(timeout 30 $BC conns "127.0.0.1:$TP_per" 3 127.0.0.2)
    check "  each address its own count: 3 from 127.0.0.2 -> 3 open ($r)" "[ '$r' = 'open=3' ]"
    r=$(timeout 30 $BC conns "unix:$SOCK_per" 5)
    check "  Unix-socket clients count as one address: 5 -> 4 open, 1 refused ($r)" \
        "[ '$r' = '503:too_many_connections=1 open=4' ]"
    r=$(timeout 30 $BC conns "127.0.0.1:$TP_per" 20 127.0.0.1,127.0.0.2,127.0.0.3,127.0.0.4,127.0.0.5)
    check "--bin-connections 16: 20 from 5 addresses (4 each) -> 16 open, 4 refused ($r)" \
        "[ '$r' = '503:too_many_connections=4 open=16' ]"
    r=$(timeout 30 $BC one "unix:$SOCK_per")
    check "the limits free up as connections close: a frame is answered 200 ($r)" "[ '$r' = 'status=200:ok' ]"
    stop_wait "$PID_per" 20
    check "SIGTERM: exit 0 ($RC)" "[ '$RC' = 0 ]"
fi

echo "-- 12: IPv6"
if python3 -c 'import socket; s = socket.socket(socket.AF_INET6); s.bind(("::1", 0))' 2>/dev/null; then
    for host in '::1' '::'; do
        if bstart v6 "[$host]:0"; then
            check "--tcp [$host]:0: log says binary protocol on tcp://[$host]:PORT" \
                "grep -q 'binary protocol on tcp://\[$host\]:$TP_v6\$' '$T/v6.log'"
            r=$(timeout 30 $BC one "[::1]:$TP_v6")
            check "  a frame over [::1]:$TP_v6: 200 ($r)" "[ '$r' = 'status=200:ok' ]"
            timeout 60 "$OBSCURA" ao tests/data/room_small.exr --camera tests/data/room_small.camera.json \
                -o "$T/v6.exr" --server "tcp://[::1]:$TP_v6" -q 2>"$T/v6.err"
            check "  obscura ao --server tcp://[::1]:$TP_v6: exit 0 ($?)" "[ -s '$T/v6.exr' ]"
            stop_wait "$PID_v6" 20
            check "  SIGTERM: exit 0 ($RC)" "[ '$RC' = 0 ]"
        fi
    done
    "$OBSCURAD" --http '' --tcp '::1:0' 2>"$T/bad6.log" &
    p=$!
    # it exits by itself: a SIGTERM at once could end the shell's child
    # before it has even opened the log
    i=0
    while [ $i -lt 100 ] && kill -0 $p 2>/dev/null; do sleep 0.1; i=$((i + 1)); done
    stop_wait $p 10
    check "--tcp ::1:0 (no brackets) is refused, names the form" \
        "[ '$RC' != 0 ] && grep -q 'IPv6 one in brackets' '$T/bad6.log'"
else
    echo "  skip IPv6 checks: ::1 is not available"
fi

[ $failed -ne 0 ] && for f in "$T"/*.log; do echo "     $f:"; tail -4 "$f" | sed 's/^/       /'; done
echo "e2e hostile_binary: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
