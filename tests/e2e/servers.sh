#!/bin/sh
# End-to-end tests of --server with a list of daemons (a farm without
# Kubernetes): `obscura batch --server A,B` spreads frames round robin over
# both; with B stopped every frame is still done (by A), with the same
# bytes as in-process; a single `obscura ao` fails over too.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/servers.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$(pwd)/$DATA/room_small.exr"
CAMF="$DATA/room_small.camera.json"
. tests/e2e/lib/common.sh

echo "e2e servers: $OBSCURA"
mkdir -p "$T/shot"
for f in 1 2 3 4 5 6; do ln -s "$R" "$T/shot/frame.000$f.exr"; done
"$OBSCURA" ao "$R" --camera "$CAMF" --samples 8 -o "$T/ref.exr" -q 2>/dev/null
same_all() { # same_all DIR: all six outputs are the reference's bytes
    for f in 1 2 3 4 5 6; do cmp -s "$T/ref.exr" "$1/ao.000$f.exr" || return 1; done
}
frames_of() { # frames_of PORT: AO requests answered 200 by that daemon
    get "$1" /metrics "$T/m" >/dev/null
    sed -n 's/^obscurad_requests_total{route="\/v1\/ao",code="200"} //p' "$T/m"
}

start A --queue 4
start B --queue 4
SOCK="$T/c.sock"
"$OBSCURAD" --http '' --socket "$SOCK" 2>"$T/C.log" &
PID_C=$!
PIDS="$PIDS $PID_C"
i=0
while [ $i -lt 300 ] && [ ! -S "$SOCK" ]; do sleep 0.1; i=$((i + 1)); done
LIST="http://127.0.0.1:$PORT_A,http://127.0.0.1:$PORT_B"

"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1-6 -o "$T/both/ao.####.exr" --camera "$CAMF" --samples 8 \
    --server "$LIST" --jobs 2 2>"$T/err"
rc=$?
na=$(frames_of "$PORT_A"); nb=$(frames_of "$PORT_B")
check "two daemons: exit $rc, 6 frames, same bytes, spread round robin ($na on A, $nb on B)" \
    "[ $rc -eq 0 ] && same_all '$T/both' && [ '${na:-0}' -eq 3 ] && [ '${nb:-0}' -eq 3 ]"

kill -TERM "$PID_B"
k=0
while [ $k -lt 100 ] && kill -0 "$PID_B" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1-6 -o "$T/one/ao.####.exr" --camera "$CAMF" --samples 8 \
    --server "$LIST" --jobs 2 2>"$T/err"
rc=$?
na2=$(frames_of "$PORT_A")
check "B stopped: exit $rc, all 6 frames done by A ($((na2 - na)) more), same bytes" \
    "[ $rc -eq 0 ] && same_all '$T/one' && [ $((na2 - na)) -eq 6 ] && grep -q '6 ok' '$T/err'"
check "B's failure said once per worker, then passed over" \
    "[ \$(grep -c 'trying the next server' '$T/err') -le 2 ] && [ \$(grep -c 'trying the next server' '$T/err') -ge 1 ]"

"$OBSCURA" ao "$R" --camera "$CAMF" --samples 8 -o "$T/single.exr" -q \
    --server "http://127.0.0.1:$PORT_B,unix:$SOCK" 2>"$T/err"
rc=$?
check "obscura ao, the first server down: the next one (binary protocol) answers; exit $rc" \
    "[ $rc -eq 0 ] && cmp -s '$T/single.exr' '$T/ref.exr'"
OBSCURA_RETRIES=1 "$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/x.exr" -q \
    --server "http://127.0.0.1:$PORT_B,unix:$T/nobody.sock" 2>"$T/err"
rc=$?
check "every server down: exit $rc (4)" "[ $rc -eq 4 ] && grep -q unreachable '$T/err'"
"$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/x.exr" -q --server "http://127.0.0.1:$PORT_A,," 2>"$T/err"
rc=$?
check "an empty list entry: usage, exit $rc (2)" "[ $rc -eq 2 ]"
"$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/x.exr" -q --stream s --server "unix:$SOCK" 2>"$T/err"
rc=$?
check "--stream over the binary protocol: usage, exit $rc (2)" "[ $rc -eq 2 ] && grep -q 'http://' '$T/err'"
[ $failed -ne 0 ] && sed 's/^/       /' "$T/err"
echo "e2e servers: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
