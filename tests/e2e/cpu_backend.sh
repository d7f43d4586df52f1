#!/bin/sh
# End-to-end tests of the CPU device's name in the CLI and the daemon:
# --backend cpu and OBSCURA_BACKEND=cpu run the chain on the CPU (no GL
# context), the same bytes as --cpu (its older name), flat and deep input;
# the frame's notes logged; --backend beats the environment; --backend auto measures the two
# devices once and keeps the faster (a run naming no backend reads it);
# `obscura info --backend cpu`; a
# backend that is none names cpu among the choices; obscurad --backend
# cpu answers frames with no GL context, its AO the CLI's --cpu AO.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/cpu_backend.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
CAMJ="$DATA/room_small.camera.json"
. tests/e2e/lib/common.sh

echo "e2e cpu_backend: $OBSCURA"
unset OBSCURA_BACKEND
"$OBSCURA" ao "$R" --camera "$CAMJ" --cpu -q -o "$T/twin.exr"
"$OBSCURA" ao "$R" --camera "$CAMJ" --backend cpu -v -o "$T/flag.exr" 2>"$T/flag.log"
rc=$?
check "--backend cpu: exit $rc, the bytes of --cpu" "[ $rc -eq 0 ] && cmp -s '$T/twin.exr' '$T/flag.exr'"
check "--backend cpu: the run line names the cpu device" "grep -q 'samples, cpu: ' '$T/flag.log'"
OBSCURA_BACKEND=cpu "$OBSCURA" ao "$R" --camera "$CAMJ" -v -o "$T/env.exr" 2>"$T/env.log"
rc=$?
check "OBSCURA_BACKEND=cpu: exit $rc, the bytes of --cpu, no GL context" \
    "[ $rc -eq 0 ] && cmp -s '$T/twin.exr' '$T/env.exr' && grep -q 'samples, cpu: ' '$T/env.log'"
OBSCURA_BACKEND=cpu "$OBSCURA" ao "$R" --camera "$CAMJ" --backend auto --cache-dir "$T/cache" -v \
    -o "$T/auto.exr" 2>"$T/auto.log"
rc=$?
# no GPU here: auto measured the CPU device against the software GL
# context and kept the faster in the cache folder
kept=$(awk 'NF == 7 && ($5 == "cpu" || $5 == "gl") { print $5 }' "$T/cache/devices.txt" 2>/dev/null)
if [ "$kept" = cpu ]; then ran='samples, cpu: '; else ran='samples, egl-'; fi
check "--backend auto beats OBSCURA_BACKEND=cpu: exit $rc, measured ($kept kept), run there" \
    "[ $rc -eq 0 ] && [ -n '$kept' ] && grep -q 'device: .*measured now' '$T/auto.log' && grep -q '$ran' '$T/auto.log'"
"$OBSCURA" ao "$R" --camera "$CAMJ" --cache-dir "$T/fresh" -v -o "$T/plain.exr" 2>"$T/plain.log"
rc=$?
check "no backend named, nothing kept, no GPU: the CPU device, not llvmpipe (exit $rc, the bytes of --cpu)" \
    "[ $rc -eq 0 ] && grep -q 'device: the CPU device (no EGL GPU device' '$T/plain.log' && cmp -s '$T/plain.exr' '$T/env.exr'"
"$OBSCURA" ao "$R" --camera "$CAMJ" --cache-dir "$T/cache" -v -o "$T/auto2.exr" 2>"$T/auto2.log"
rc=$?
check "no backend named: exit $rc, the kept choice ($kept), not measured again" \
    "[ $rc -eq 0 ] && grep -q 'device: .*measured before' '$T/auto2.log' && grep -q '$ran' '$T/auto2.log' && [ \$(wc -l < '$T/cache/devices.txt') -eq 1 ]"

"$OBSCURA" ao "$R" --preset blender --fov-y 50 --backend cpu -o "$T/fov.exr" 2>"$T/fov.log"
rc=$?
check "--backend cpu logs the frame's notes as a GL context does (exit $rc)" \
    "[ $rc -eq 0 ] && grep -q 'reconstructing normals from depth' '$T/fov.log'"

"$OBSCURA" ao "$DATA/deep_small.exr" --radius 0.6 --cpu -q -o "$T/deep_twin.exr"
"$OBSCURA" ao "$DATA/deep_small.exr" --radius 0.6 --backend cpu -q -o "$T/deep_flag.exr"
rc=$?
check "deep input, --backend cpu: exit $rc, the bytes of --cpu" \
    "[ $rc -eq 0 ] && cmp -s '$T/deep_twin.exr' '$T/deep_flag.exr'"

printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$T/tri.obj"
"$OBSCURA" gbuffer "$T/tri.obj" --camera "$CAMJ" --backend cpu -o "$T/g.exr" 2>"$T/g.err"
rc=$?
check "gbuffer --backend cpu: usage error (exit $rc): it rasterises, GL needed" \
    "[ $rc -eq 2 ] && grep -q 'rasterises a mesh, which needs a GL context' '$T/g.err'"
"$OBSCURA" warmup --backend cpu --cache-dir "$T/wc" 2>"$T/w.err"
rc=$?
check "warmup --backend cpu: exit $rc, nothing to warm up" \
    "[ $rc -eq 0 ] && grep -q 'compiles no programs' '$T/w.err'"

out=$("$OBSCURA" info --backend cpu 2>&1)
rc=$?
check "info --backend cpu: exit $rc, 'backend: cpu'" \
    "[ $rc -eq 0 ] && echo \"\$out\" | grep -q '^backend: cpu'"
"$OBSCURA" ao "$R" --camera "$CAMJ" --backend cpux -o "$T/x.exr" 2>"$T/err"
rc=$?
check "--backend cpux: usage error (exit $rc) listing cpu" \
    "[ $rc -eq 2 ] && grep -q 'auto|cpu|egl-device' '$T/err'"
check "help: --backend lists cpu, --cpu is its synonym" \
    "'$OBSCURA' ao --help 2>&1 | grep -q 'auto|cpu|' && '$OBSCURA' ao --help 2>&1 | grep -q 'same as --backend cpu'"

echo "-- obscurad --backend cpu"
start d --backend cpu
check "the log names the cpu backend, no GL context" "grep -q 'backend cpu' '$T/d.log'"
W2C=$(tr -d ' \n' < "$CAMJ" |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
CAM="fov_y=50&near=0.05&far=100&world_to_camera=$W2C"
code=$(post "$PORT_d" "$CAM&format=exr&float=1" "$R" "$T/d.exr")
"$OBSCURA" ao "$R" --fov-y 50 --near 0.05 --far 100 --world-to-camera "$W2C" --cpu --float -q \
    -o "$T/cli.exr"
check "a frame: HTTP $code, its AO the CLI's --cpu AO" \
    "[ '$code' = 200 ] && '$OBSCURA' compare '$T/cli.exr' '$T/d.exr' --mask none --json 2>/dev/null | grep -q '\"mae\": *0[,}]'"
code=$(get "$PORT_d" /v1/info "$T/info.json")
check "/v1/info: HTTP $code, backend cpu" "[ '$code' = 200 ] && grep -q '\"backend\":[[:space:]]*\"cpu\"' '$T/info.json'"
kill "$PID_d" 2>/dev/null
wait "$PID_d" 2>/dev/null

echo "e2e cpu_backend: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
