#!/bin/sh
# End-to-end tests of obscurad's work and memory limits: --max-cost
# refuses a frame that asks for more samples than it allows (422
# too_costly, naming the option) before running it, over HTTP and the
# binary protocol, and lets a cheaper one through; --keep-memory bounds the
# texture memory the GL worker keeps for the next frame (the gauge
# obscurad_gl_kept_bytes of /metrics), which is released when the queue
# runs empty, and freed heap memory is returned to the system once the
# queue has stayed empty for a second; --frame-deadline stops a frame whose GL work runs past it
# (422 deadline_exceeded, naming the option), and the GL worker goes on
# with the next frame.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/limits.sh
#
# Every daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
UPSCALE=${UPSCALE:-$(dirname "$OBSCURA")/exr_upscale}
R=tests/data/room_small.exr
CAM=tests/data/room_small.camera.json
. tests/e2e/lib/common.sh

# metric PORT NAME: the value of a gauge
metric() { $CURL "http://127.0.0.1:$1/metrics" | sed -n "s/^$2 \([0-9.e+]*\)$/\1/p"; }
Q="fov_y=50&near=0.05&far=100"

echo "e2e limits: $OBSCURAD"
# room_small is 320x240: 76800 pixels x 16 samples = 1228800 samples
start C --max-cost 1m --socket "$T/c.sock"
st=$(post "$PORT_C" "$Q" "$R" "$T/c1.json")
check "--max-cost 1m: 320x240 x 16 samples (1228800) is 422 too_costly ($st)" \
    "[ '$st' = 422 ] && error_is '$T/c1.json' too_costly && grep -q 'max-cost' '$T/c1.json'"
st=$(post "$PORT_C" "$Q&samples=8" "$R" "$T/c2.out")
check "--max-cost 1m: 8 samples (614400) is answered ($st)" "[ '$st' = 200 ]"
st=$(post "$PORT_C" "$Q&method=hbao&hbao_directions=32&hbao_steps=32" "$R" "$T/c3.json")
check "--max-cost 1m: hbao 32 x 32 counts its 1024 samples per pixel: 422 ($st)" \
    "[ '$st' = 422 ] && error_is '$T/c3.json' too_costly"
"$OBSCURA" ao "$R" --camera "$CAM" -o "$T/c4.exr" --server "unix:$T/c.sock" -q 2>"$T/c4.err"
rc=$?
check "--max-cost over the binary protocol: the CLI exits 3 and shows why (rc $rc)" \
    "[ $rc -eq 3 ] && grep -q 'max-cost' '$T/c4.err'"
$CURL "http://127.0.0.1:$PORT_C/metrics" > "$T/c.metrics"
computed=$(sed -n 's/^obscurad_frames_total{[^}]*} \([0-9]*\)$/\1/p' "$T/c.metrics" | awk '{s += $1} END {print s + 0}')
check "the refused frames were not computed: one frame in obscurad_frames_total ($computed)" \
    "[ '$computed' = 1 ] && grep -q 'obscurad_requests_total{route=\"/v1/ao\",code=\"422\"} 2' '$T/c.metrics'"

# The kept targets of a 320x240 AO frame with normals derived from depth:
# 4612800 bytes, 60 a pixel and the culling pre-pass's 1/8-size plane
# (test_kept.c counts the same textures)
# (on the CPU device, its one block of planes: a size of its own, at
# least the 36 bytes a pixel of the position, normal, AO and blur planes,
# and above the 1m below)
start K
st=$(post "$PORT_K" "$Q" "$R" "$T/k1.out")
kept=$(metric "$PORT_K" obscurad_gl_kept_bytes)
if [ "$CPU_DEVICE" = 1 ]; then
    check "default --keep-memory: the CPU device's planes are kept for the next frame ($kept bytes)" \
        "[ '$st' = 200 ] && [ '${kept:-0}' -ge $((320 * 240 * 36)) ] && [ '${kept:-0}' -lt $((16 * 1048576)) ]"
else
    check "default --keep-memory: a frame's targets are kept for the next ($kept bytes)" \
        "[ '$st' = 200 ] && [ '$kept' = 4612800 ]"
fi
start M --keep-memory 1m
st=$(post "$PORT_M" "$Q" "$R" "$T/m1.out")
kept=$(metric "$PORT_M" obscurad_gl_kept_bytes)
check "--keep-memory 1m: released once the queue ran empty ($kept bytes kept)" \
    "[ '$st' = 200 ] && [ '$kept' = 0 ]"
st=$(post "$PORT_M" "$Q" "$R" "$T/m2.out")
check "--keep-memory 1m: the next frame is the same ($st)" "[ '$st' = 200 ] && cmp -s '$T/m1.out' '$T/m2.out'"

# Freed heap goes back to the system once the queue has stayed empty for
# a second: not between frames sent one after another, once after them,
# and not again while nothing runs.
start H
for i in 1 2 3; do post "$PORT_H" "$Q" "$R" "$T/h$i.out" > "$T/h$i.st"; done
t_now=$(metric "$PORT_H" obscurad_heap_trims_total)
sleep 2
t_idle=$(metric "$PORT_H" obscurad_heap_trims_total)
sleep 2
t_later=$(metric "$PORT_H" obscurad_heap_trims_total)
check "heap trimmed once, a second after 3 back-to-back frames (trims: $t_now, then $t_idle, then $t_later)" \
    "[ '$t_now' = 0 ] && [ '$t_idle' = 1 ] && [ '$t_later' = 1 ] && [ \"\$(cat '$T/h1.st' '$T/h2.st' '$T/h3.st')\" = 200200200 ]"

# --frame-deadline: HBAO 32 x 32 on a 1920x1080 frame holds the GL worker
# for 8.7 s on llvmpipe (2 cores; answered 200 with no deadline); with a
# 1 s deadline it is stopped within one of the AO pass's 16 bands past it.
if "$UPSCALE" "$R" 1920x1080 "$T/hd.exr" 2>"$T/up.err"; then
    HEAVY="$Q&method=hbao&hbao_directions=32&hbao_steps=32"
    start D --frame-deadline 1 --max-cost 0 --socket "$T/d.sock"
    t0=$(date +%s%N)
    st=$(post "$PORT_D" "$HEAVY" "$T/hd.exr" "$T/d1.json")
    took=$(( ($(date +%s%N) - t0) / 1000000 ))
    check "--frame-deadline 1: an 8.7 s frame is 422 deadline_exceeded in $took ms, naming the option ($st)" \
        "[ '$st' = 422 ] && error_is '$T/d1.json' deadline_exceeded && grep -q 'frame-deadline' '$T/d1.json' && [ $took -lt 5000 ]"
    "$OBSCURA" ao "$T/hd.exr" --camera "$CAM" --method hbao --hbao-directions 32 --hbao-steps 32 \
        -o "$T/d2.exr" --server "unix:$T/d.sock" -q 2>"$T/d2.err"
    rc=$?
    check "--frame-deadline over the binary protocol: the CLI exits 3 and shows why (rc $rc)" \
        "[ $rc -eq 3 ] && grep -q 'frame-deadline' '$T/d2.err'"
    st=$(post "$PORT_D" "$Q" "$R" "$T/d3.out")
    start E --frame-deadline 0
    st0=$(post "$PORT_E" "$Q" "$R" "$T/e3.out")
    check "after a cut frame the next is answered, the same as with no deadline ($st, $st0)" \
        "[ '$st' = 200 ] && [ '$st0' = 200 ] && cmp -s '$T/d3.out' '$T/e3.out'"
else
    bad "exr_upscale 1280x720: $(cat "$T/up.err")"
fi

echo "e2e limits: $pass passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
