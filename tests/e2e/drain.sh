#!/bin/sh
# End-to-end test of the drain deadline: after SIGTERM obscurad waits for
# the requests under way at most --drain-timeout seconds, then cuts what
# is left, logs what it cut and exits 0.  The client that holds the drain
# sends its body a byte every half second (each gap shorter than
# --timeout, the whole request shorter than --request-timeout), so only
# the drain deadline ends it.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/drain.sh
#
# Every daemon and client it starts is killed on exit; every wait is
# bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
. tests/e2e/lib/common.sh

# trickle PORT SECONDS FILE: a POST /v1/ao whose body comes a byte every
# 0.5 s; FILE is made once its headers and first byte are sent
trickle() {
    python3 - "$1" "$2" "$3" <<'PY'
import socket, sys, time
port, seconds = int(sys.argv[1]), float(sys.argv[2])
s = socket.create_connection(("127.0.0.1", port), timeout=5)
s.sendall(b"POST /v1/ao HTTP/1.1\r\nHost: x\r\nContent-Type: image/x-exr\r\n"
          b"Content-Length: 100000\r\n\r\nv")
open(sys.argv[3], "w").close()
end = time.time() + seconds
try:
    while time.time() < end:
        s.sendall(b"v")
        time.sleep(0.5)
except OSError:
    pass  # the daemon cut the connection
PY
}

echo "e2e drain: $OBSCURAD"
start D --drain-timeout 2 --timeout 30
trickle "$PORT_D" 30 "$T/sent" &
CPIDS=$!
# the request is under way (a loaded machine may take seconds to start
# python) before the signal
i=0
while [ ! -f "$T/sent" ] && [ $i -lt 200 ]; do sleep 0.1; i=$((i + 1)); done
sleep 0.5
t0=$(date +%s)
kill -TERM "$PID_D"
i=0
while kill -0 "$PID_D" 2>/dev/null && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
t1=$(date +%s)
if kill -0 "$PID_D" 2>/dev/null; then
    bad "SIGTERM with a trickling client: not exited 10 s after the signal"
else
    wait "$PID_D"
    rc=$?
    check "SIGTERM with a trickling client: exit $rc within the 2 s drain deadline (+1 s), $((t1 - t0)) s" \
        "[ $rc -eq 0 ] && [ $((t1 - t0)) -le 4 ]"
fi
check "the log names what the deadline cut" "grep -q 'drain deadline (2 s) passed: cutting 1 request' '$T/D.log'"

echo "e2e drain: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
