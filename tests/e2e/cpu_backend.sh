#!/bin/sh
# End-to-end tests of the CPU device's name in the CLI: --backend cpu and
# OBSCURA_BACKEND=cpu run the chain on the CPU (no GL context), the same
# bytes as --cpu (its older name), flat and deep input; --backend beats
# the environment; `obscura info --backend cpu`; a backend that is none
# names cpu among the choices.
#
#   OBSCURA=build/obscura tests/e2e/cpu_backend.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
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
OBSCURA_BACKEND=cpu "$OBSCURA" ao "$R" --camera "$CAMJ" --backend auto -v -o "$T/gl.exr" 2>"$T/gl.log"
rc=$?
check "--backend auto beats OBSCURA_BACKEND=cpu: exit $rc, a GL context" \
    "[ $rc -eq 0 ] && ! grep -q 'samples, cpu: ' '$T/gl.log' && grep -q 'samples, ' '$T/gl.log'"

"$OBSCURA" ao "$DATA/deep_small.exr" --radius 0.6 --cpu -q -o "$T/deep_twin.exr"
"$OBSCURA" ao "$DATA/deep_small.exr" --radius 0.6 --backend cpu -q -o "$T/deep_flag.exr"
rc=$?
check "deep input, --backend cpu: exit $rc, the bytes of --cpu" \
    "[ $rc -eq 0 ] && cmp -s '$T/deep_twin.exr' '$T/deep_flag.exr'"

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

echo "e2e cpu_backend: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
