#!/bin/sh
# End-to-end tests of the thread limit: `--threads N` (else
# OBSCURA_THREADS) on obscura's commands and `--render-threads N` on
# obscurad set llvmpipe's LP_NUM_THREADS (unless the user set it) and
# bound every worker pool; the process's threads (/proc/PID/task) follow
# N; outputs are the same bytes for 1 and 2 threads (ao, batch, a small
# bake); bad values are a usage error (exit 2) naming the flag.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/threads.sh
#
# The daemons it starts are killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
R=tests/data/room_small.exr
CAMF=tests/data/room_small.camera.json
FIX=tests/data/levels/aalborg_cut.acc
. tests/e2e/lib/common.sh

# info_threads ARGS...: the process's threads once obscura info made its context
info_threads() { "$OBSCURA" info "$@" 2>/dev/null | sed -n 's/^process threads: //p'; }

echo "e2e threads: $OBSCURA"
LLVMPIPE=0
unset LP_NUM_THREADS OBSCURA_THREADS
"$OBSCURA" info | grep -q '^GL renderer: llvmpipe' && LLVMPIPE=1

echo "-- obscura info: the limit, llvmpipe's count and the process's threads"
expect 0 "info --threads 1" -- "$OBSCURA" info --threads 1
said "threads: 1 (--threads"
t1=$(info_threads --threads 1); t2=$(info_threads --threads 2); t4=$(info_threads --threads 4)
if [ $LLVMPIPE = 1 ]; then
    said "llvmpipe threads: 1 (LP_NUM_THREADS set from --threads)"
    check "the process's threads grow with --threads (1: $t1, 2: $t2, 4: $t4)" \
        "[ -n '$t1' ] && [ $t1 -lt $t2 ] && [ $t2 -lt $t4 ]"
    LP_NUM_THREADS=4 "$OBSCURA" info --threads 1 >"$T/out" 2>"$T/err"
    said "llvmpipe threads: 4 (LP_NUM_THREADS from the environment, kept)"
    tu=$(LP_NUM_THREADS=4 info_threads --threads 1)
    check "the user's LP_NUM_THREADS wins over --threads ($tu threads, as --threads 4)" "[ '$tu' = '$t4' ]"
    to=$(OBSCURA_THREADS=1 info_threads)
    check "OBSCURA_THREADS=1 as --threads 1 ($to threads)" "[ '$to' = '$t1' ]"
    tb=$(OBSCURA_THREADS=4 info_threads --threads 1)
    check "--threads over OBSCURA_THREADS ($tb threads)" "[ '$tb' = '$t1' ]"
elif [ "$CPU_DEVICE" = 1 ]; then
    said "llvmpipe threads: not in use"
    skip "llvmpipe's threads and the process's count after info: GL only (the CPU device makes no context; its threads start with a frame)"
else
    ok "not llvmpipe: its thread count is not checked"
fi

echo "-- obscura ao: the frame's threads, the same bytes"
ao_threads() { sed -n 's/.*debug: threads: \([0-9]*\) in this process.*/\1/p' "$T/err"; }
expect 0 "ao --threads 1" -- "$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/a1.exr" --threads 1 -v
a1=$(ao_threads)
expect 0 "ao --threads=2" -- "$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/a2.exr" --threads=2 -v
a2=$(ao_threads)
expect 0 "ao without --threads" -- "$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/a0.exr" -q
check "ao: the same EXR bytes for 1, 2 and every core" "cmp -s $T/a1.exr $T/a2.exr && cmp -s $T/a1.exr $T/a0.exr"
if [ $LLVMPIPE = 1 ]; then
    check "ao: fewer threads with --threads 1 ($a1) than 2 ($a2), as info's ($t1)" \
        "[ -n '$a1' ] && [ $a1 -lt $a2 ] && [ $a1 -eq $t1 ]"
elif [ "$CPU_DEVICE" = 1 ]; then
    # the CPU device's pool threads run a pass and are joined: none is
    # left once the frame is done, whatever --threads; while the frame
    # runs (a 640x480 HBAO frame: about a second) the process's threads,
    # read every few milliseconds, never pass --threads, and reach it or
    # the cores, whichever is fewer
    check "ao on the CPU device: its threads end with the frame (1 thread left after it: $a1, $a2)" \
        "[ '$a1' = 1 ] && [ '$a2' = 1 ]"
    # peak N: the most threads obscura ao --threads N had at once
    peak() {
        "$OBSCURA" ao "$T/mid.exr" --camera "$CAMF" --method hbao --hbao-directions 16 --hbao-steps 16 \
            -o "$T/peak$1.exr" --threads "$1" -q &
        p=$! most=0
        while kill -0 $p 2>/dev/null; do
            n=$(ls /proc/$p/task 2>/dev/null | wc -l)
            [ "$n" -gt "$most" ] && most=$n
            sleep 0.01
        done
        wait $p
        echo "$most"
    }
    if "${BUILD:-build}/exr_upscale" "$R" 640x480 "$T/mid.exr" 2>"$T/up.err"; then
        m1=$(peak 1); m3=$(peak 3)
        cores=$(nproc); [ "$cores" -gt 3 ] && cores=3
        check "ao on the CPU device: min(--threads, cores) threads while the frame runs (1: $m1, 3: $m3 of $cores)" \
            "[ '$m1' = 1 ] && [ '$m3' = $cores ] && cmp -s $T/peak1.exr $T/peak3.exr"
    else
        bad "exr_upscale 640x480 (make e2e builds it): $(cat "$T/up.err")"
    fi
fi
expect 0 "ao --threads 1, PNG" -- "$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/p1.png" --threads 1 -q
expect 0 "ao --threads 2, PNG" -- "$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/p2.png" --threads 2 -q
check "ao: the same PNG bytes" "cmp -s $T/p1.png $T/p2.png"
expect 0 "ao --help names --threads" -- "$OBSCURA" ao --help
said "--threads N"
expect 0 "bake --help names --threads" -- "$OBSCURA" bake --help
said "^--threads N (or OBSCURA_THREADS)"
expect 2 "ao --thread 2: unknown" -- "$OBSCURA" ao "$R" -o "$T/x.exr" --thread 2
said "did you mean --threads?"

echo "-- obscura batch"
mkdir -p "$T/shot"
for f in 1 2; do ln -s "$(pwd)/$R" "$T/shot/f.000$f.exr"; done
expect 0 "batch --threads 1" -- "$OBSCURA" batch "$T/shot/f.####.exr" --frames 1-2 -o "$T/b/ao.####.exr" \
    --camera "$CAMF" --threads 1 -q
check "batch: each frame the bytes of obscura ao" "cmp -s $T/a1.exr $T/b/ao.0001.exr && cmp -s $T/a1.exr $T/b/ao.0002.exr"

echo "-- the bakes: the flag is the table's threads parameter"
expect 0 "bake --threads 1" -- "$OBSCURA" bake "$FIX" -o "$T/k1.glb" --rays 8 --threads 1 --report "$T/k1.json" -q
expect 0 "bake --threads 2" -- "$OBSCURA" bake "$FIX" -o "$T/k2.glb" --rays 8 --threads 2 -q
check "bake: the same bytes for 1 and 2 threads" "cmp -s $T/k1.glb $T/k2.glb"
check "bake: the report's threads parameter is --threads" \
    "python3 -c \"import json,sys; sys.exit(json.load(open('$T/k1.json'))['params']['threads'] != 1)\""

echo "-- bad values: a usage error naming the flag"
for v in -1 abc 65 1.5 ''; do
    expect 2 "ao --threads '$v'" -- "$OBSCURA" ao "$R" -o "$T/x.exr" --threads "$v"
    said "--threads: '$v' is not a whole number in \[0, 64\]"
done
expect 2 "ao --threads with no value" -- "$OBSCURA" ao "$R" -o "$T/x.exr" --threads
said "option --threads needs a value"
expect 2 "batch --threads 65" -- "$OBSCURA" batch "$T/shot/f.####.exr" --frames 1-2 -o "$T/c/ao.####.exr" --threads 65
expect 2 "bake --threads -2" -- "$OBSCURA" bake "$FIX" -o "$T/x.glb" --threads -2
said "bake: --threads: '-2' is not"
expect 2 "bake-dynamic --threads abc" -- "$OBSCURA" bake-dynamic "$FIX" -o "$T/x.json" --threads abc
expect 2 "OBSCURA_THREADS=abc" -- env OBSCURA_THREADS=abc "$OBSCURA" ao "$R" -o "$T/x.exr"
said "OBSCURA_THREADS: 'abc' is not a whole number"
# 0: every core, as the bakes' threads parameter (the farm templates' default)
expect 0 "bake --threads 0 (every core)" -- "$OBSCURA" bake "$FIX" -o "$T/k0.glb" --rays 8 --threads 0 -q
check "bake: --threads 0 gives the same bytes as 1" "cmp -s $T/k0.glb $T/k1.glb"
rm -f "$T/k0.glb"
check "nothing written on a usage error" "[ ! -e $T/x.exr ] && [ ! -e $T/x.glb ] && [ ! -d $T/c ]"

echo "-- obscurad: --render-threads (--threads stays the HTTP pool)"
# daemon_threads NAME: the daemon's threads once it answered a frame
daemon_threads() {
    eval "p=\$PORT_$1 pid=\$PID_$1"
    st=$(post "$p" "" "$R" "$T/$1.exr")
    [ "$st" = 200 ] && ls "/proc/$pid/task" | wc -l
}
start D1 --render-threads 1
start D3 --render-threads 3 --threads 4
d1=$(daemon_threads D1); d3=$(daemon_threads D3)
check "a frame through each (200)" "[ -n '$d1' ] && [ -n '$d3' ]"
check "the log says the render threads" "grep -q 'threads: render 1 (--render-threads' $T/D1.log"
check "the same AO bytes for 1 and 3 render threads" "cmp -s $T/D1.exr $T/D3.exr"
if [ "$CPU_DEVICE" = 1 ]; then
    check "the CPU device's log: llvmpipe not in use" "grep -q 'llvmpipe not in use' $T/D3.log"
    skip "the daemon's threads against --render-threads: GL only (llvmpipe's threads stay with the context; the CPU device's end with each pass)"
elif [ $LLVMPIPE = 1 ]; then
    check "llvmpipe's count in the log" "grep -q 'llvmpipe 3 (LP_NUM_THREADS set from the render threads)' $T/D3.log"
    check "the daemon's threads follow --render-threads (1: $d1, 3: $d3)" "[ -n '$d1' ] && [ $d1 -lt $d3 ]"
fi
kill $PID_D1 $PID_D3 2>/dev/null
expect 2 "obscurad --render-threads abc" -- "$OBSCURAD" --http 127.0.0.1:0 --render-threads abc
said "render_threads: 'abc' is not a number"
expect 2 "obscurad with OBSCURA_THREADS=abc" -- env OBSCURA_THREADS=abc "$OBSCURAD" --http 127.0.0.1:0
said "OBSCURA_THREADS: option render_threads: 'abc'"

echo "e2e threads: $pass passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
