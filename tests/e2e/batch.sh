#!/bin/sh
# End-to-end tests of `obscura batch`: a few frames (links to
# tests/data/room_small.exr) in-process and through obscurad (HTTP, Unix
# socket, --jobs) give the same files as single `obscura ao` runs; a
# missing frame is exit 3 with the others written (--allow-missing: 0), a
# batch that wrote nothing is never 0 (a padding mismatch included),
# --strict only makes warnings errors, -q quiets the frame lines,
# --progress percent prints "Progress: N%", bad usage is 2 and an
# unreachable server 4.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/batch.sh
#
# The daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$(pwd)/$DATA/room_small.exr"
CAMF="$DATA/room_small.camera.json"
. tests/e2e/lib/common.sh
PID=""

echo "e2e batch: $OBSCURA"
mkdir -p "$T/shot"
for f in 1 3 5; do ln -s "$R" "$T/shot/frame.000$f.exr"; done
# the reference: one `obscura ao` per frame (all frames are the same input)
"$OBSCURA" ao "$R" --camera "$CAMF" --radius 0.4 -o "$T/ref.exr" -q 2>/dev/null
same_all() { # same_all DIR NAMES...: every file is the reference's bytes
    d=$1; shift
    for n in "$@"; do cmp -s "$T/ref.exr" "$d/$n" || return 1; done
}

echo "-- in-process"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1-5x2 -o "$T/a/ao.%04d.exr" --camera "$CAMF" --radius 0.4 2>"$T/err"
rc=$?
check "1-5x2: exit $rc, three frames, same bytes as obscura ao" \
    "[ $rc -eq 0 ] && same_all '$T/a' ao.0001.exr ao.0003.exr ao.0005.exr"
check "plain progress lines when stderr is no terminal" "grep -q 'batch: \[3/3\] frame 5 ok' '$T/err'"
check "one GL context for all frames (one worker, no per-frame context)" \
    "[ \$(grep -c 'frame .* ok' '$T/err') -eq 3 ]"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1-3,5 -o "$T/b/ao.####.exr" --camera "$CAMF" --radius 0.4 2>"$T/err"
rc=$?
check "a missing frame (2): exit $rc (3), the others still written" \
    "[ $rc -eq 3 ] && grep -q 'error: batch: frame 2: missing input' '$T/err' && grep -q '1 missing' '$T/err' && same_all '$T/b' ao.0001.exr ao.0003.exr ao.0005.exr && [ ! -e '$T/b/ao.0002.exr' ]"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1-3,5 -o "$T/b2/ao.####.exr" --camera "$CAMF" --radius 0.4 --allow-missing 2>"$T/err"
rc=$?
check "--allow-missing accepts the gap: exit $rc (0), a warning" \
    "[ $rc -eq 0 ] && grep -q 'warning: batch: frame 2: missing input' '$T/err' && same_all '$T/b2' ao.0001.exr ao.0003.exr ao.0005.exr"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 2,4 -o "$T/b3/ao.####.exr" --camera "$CAMF" --allow-missing 2>"$T/err"
rc=$?
check "--allow-missing, every input missing: nothing written, exit $rc (3)" "[ $rc -eq 3 ] && grep -q 'nothing written' '$T/err'"
"$OBSCURA" batch "$T/shot/frame.##.exr" --frames 1-5 -o "$T/b4/ao.####.exr" --camera "$CAMF" 2>"$T/err"
rc=$?
check "padding mismatch (frame.##.exr vs frame.0001.exr): exit $rc (3), not 0" "[ $rc -eq 3 ] && grep -q '0 ok' '$T/err'"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1-3 -o "$T/c/ao.####.exr" --camera "$CAMF" --strict 2>"$T/err"
rc=$?
check "--strict with a missing frame: exit $rc (3), the warning-free frames still written" \
    "[ $rc -eq 3 ] && [ -e '$T/c/ao.0001.exr' ] && [ -e '$T/c/ao.0003.exr' ]"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1,3 -o "$T/q/ao.####.exr" --camera "$CAMF" -q 2>"$T/err"
rc=$?
check "-q: exit $rc, no frame lines, no summary" "[ $rc -eq 0 ] && [ ! -s '$T/err' ]"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1,3,5 -o "$T/p/ao.####.exr" --camera "$CAMF" --progress percent >"$T/out" 2>"$T/err"
rc=$?
check "--progress percent: exit $rc, Progress: 33% 66% 100% on stdout" \
    "[ $rc -eq 0 ] && [ \"\$(tr '\\n' ' ' < '$T/out')\" = 'Progress: 33% Progress: 66% Progress: 100% ' ]"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1 -o "$T/p/ao.####.exr" --progress bar 2>"$T/err"
rc=$?
check "--progress bar: exit $rc (2)" "[ $rc -eq 2 ] && grep -q 'not plain or percent' '$T/err'"
"$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1 -o "$T/d/ao.####.exr" --solve-camera=0 2>"$T/err"
rc=$?
check "no camera (and its position pass not solved): the frame's bad input is exit $rc (3)" "[ $rc -eq 3 ] && grep -q '1 failed' '$T/err'"
for args in "--frames 1-x -o $T/e.####.exr" "--frames 1 -o $T/e.exr" "--frames 1 -o $T/e.#.exr --no-such-flag 1" \
    "--frames 1 -o $T/e.#.exr --jobs 2" "-o $T/e.#.exr"; do
    # shellcheck disable=SC2086
    "$OBSCURA" batch "$T/shot/frame.####.exr" $args --camera "$CAMF" 2>"$T/err"
    rc=$?
    check "usage: '$args': exit $rc (2)" "[ $rc -eq 2 ]"
done

echo "-- through obscurad"
SOCK="$T/obscurad.sock"
"$OBSCURAD" --http 127.0.0.1:0 --socket "$SOCK" --queue 4 2>"$T/d.log" &
PID=$!
i=0; HP=""
while [ $i -lt 300 ] && { [ -z "$HP" ] || [ ! -S "$SOCK" ]; }; do
    HP=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/d.log")
    kill -0 "$PID" 2>/dev/null || break
    sleep 0.1
    i=$((i + 1))
done
if [ -n "$HP" ] && [ -S "$SOCK" ]; then ok "obscurad on http :$HP and unix:$SOCK"; else
    bad "obscurad did not start"; tail -5 "$T/d.log"; exit 1; fi
for url in "unix:$SOCK" "http://127.0.0.1:$HP"; do
    o="$T/r_${url%%:*}"
    "$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1-5 -o "$o/ao.####.exr" --camera "$CAMF" --radius 0.4 \
        --server "$url" --jobs 3 2>"$T/err"
    rc=$?
    check "--server ${url%%:*} --jobs 3: exit $rc (3), same bytes as obscura ao, 2 missing reported" \
        "[ $rc -eq 3 ] && same_all '$o' ao.0001.exr ao.0003.exr ao.0005.exr && grep -q '2 missing' '$T/err'"
done
kill -TERM "$PID"; k=0
while [ $k -lt 100 ] && kill -0 "$PID" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
PID=""

echo "-- server unreachable"
OBSCURA_RETRIES=1 "$OBSCURA" batch "$T/shot/frame.####.exr" --frames 1-5 -o "$T/u/ao.####.exr" --camera "$CAMF" \
    --server "unix:$T/nobody.sock" --jobs 2 2>"$T/err"
rc=$?
check "nobody listening: exit $rc (4), frames not run after the first failure reported" \
    "[ $rc -eq 4 ] && grep -q 'unreachable' '$T/err' && grep -q 'not run\|failed' '$T/err'"
[ $failed -ne 0 ] && sed 's/^/       /' "$T/err"
echo "e2e batch: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
