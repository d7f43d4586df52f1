#!/bin/sh
# End-to-end tests of a frame by rows on the CPU device (obscura ao, README
# "Frames larger than memory"): with OBSCURA_BAND_ROWS (or a frame over
# --max-memory, else OBSCURA_MAX_MEMORY) a flat EXR is read by rows, run in
# bands and written by rows, and the output file is the whole frame's, byte
# for byte (AO, composite as float with PIZ, half resolution, another
# method); outputs the rows path does not write (PNG) and deep input run
# whole, as before.  --max-memory: over the environment, a bad value
# refused naming it, a band over it said at the default verbosity; obscurad
# --max-memory: the frame in bands in memory, the same AO bytes.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/bands.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
CAMJ="$DATA/room_small.camera.json"
. tests/e2e/lib/common.sh

echo "e2e bands: $OBSCURA"
unset OBSCURA_BAND_ROWS OBSCURA_MAX_MEMORY

# same NAME ARGS...: the frame whole and by rows (bands of 24 rows), the
# same bytes, and the rows path taken
same() {
    name=$1; shift
    "$OBSCURA" ao "$@" --backend cpu -q -o "$T/$name.whole.exr"
    OBSCURA_BAND_ROWS=24 "$OBSCURA" ao "$@" --backend cpu -v -o "$T/$name.rows.exr" 2>"$T/$name.log"
    rc=$?
    check "$name: exit $rc by rows, the whole frame's file byte for byte" \
        "[ $rc -eq 0 ] && cmp -s '$T/$name.whole.exr' '$T/$name.rows.exr'"
    check "$name: read, run and written by rows, in bands" \
        "grep -q 'by rows' '$T/$name.log' && grep -q 'band 3: rows' '$T/$name.log'"
}
same default "$R" --camera "$CAMJ"
same composite_float "$R" --camera "$CAMJ" --output ao,composite --float --compression piz
same half "$R" --camera "$CAMJ" --ao-resolution half --luminance lum
same gtao "$DATA/yard_small.exr" --camera "$DATA/yard_small.camera.json" --method gtao

# a budget the frame is over: by rows with no band count given
OBSCURA_MAX_MEMORY=1 "$OBSCURA" ao "$R" --camera "$CAMJ" --backend cpu -v -o "$T/budget.exr" 2>"$T/budget.log"
rc=$?
check "OBSCURA_MAX_MEMORY=1: exit $rc, by rows, the whole frame's file" \
    "[ $rc -eq 0 ] && grep -q 'by rows' '$T/budget.log' && cmp -s '$T/default.whole.exr' '$T/budget.exr'"

# --max-memory: as OBSCURA_MAX_MEMORY, and over it; the band over the
# budget is a warning at the default verbosity, naming the option
"$OBSCURA" ao "$R" --camera "$CAMJ" --backend cpu --max-memory 1 -o "$T/opt.exr" 2>"$T/opt.log"
rc=$?
check "--max-memory 1: exit $rc, by rows, the whole frame's file" \
    "[ $rc -eq 0 ] && grep -q 'by rows' '$T/opt.log' && cmp -s '$T/default.whole.exr' '$T/opt.exr'"
check "--max-memory 1: the log names the budget and the option" \
    "grep -q 'over the memory budget of 1 MiB (--max-memory)' '$T/opt.log'"
check "--max-memory 1, no -v: a warning names the option and the halo's rows" \
    "grep -q \"^obscura: warning: --max-memory 1 MiB: the AO's samples reach up to [0-9]* rows either side\" '$T/opt.log'"
OBSCURA_MAX_MEMORY=1 "$OBSCURA" ao "$R" --camera "$CAMJ" --backend cpu --max-memory 1000 -v -o "$T/over.exr" 2>"$T/over.log"
rc=$?
check "--max-memory 1000 over OBSCURA_MAX_MEMORY=1: exit $rc, the frame whole, the budget said with -v" \
    "[ $rc -eq 0 ] && ! grep -q 'by rows' '$T/over.log' && grep -q 'memory budget: 1000 MiB (--max-memory)' '$T/over.log'"
"$OBSCURA" ao "$R" --camera "$CAMJ" --backend cpu -v -o "$T/def.exr" 2>"$T/def.log"
check "no budget given: -v says the default, a quarter of the usable memory" \
    "grep -q 'memory budget: [0-9]* MiB (default: a quarter of' '$T/def.log'"
expect 2 "--max-memory 0: usage error" -- "$OBSCURA" ao "$R" --backend cpu --max-memory 0 -o "$T/x.exr"
said "ao: --max-memory: '0' is not a whole number of MiB from 1 to"
expect 2 "--max-memory 12abc: usage error" -- "$OBSCURA" ao "$R" --backend cpu --max-memory 12abc -o "$T/x.exr"
said "ao: --max-memory: '12abc' is not a whole number of MiB"
expect 2 "--max-memory over the usable memory: usage error" -- "$OBSCURA" ao "$R" --backend cpu --max-memory 999999999 -o "$T/x.exr"
said "ao: --max-memory: 999999999 MiB is more than the usable memory"
expect 2 "OBSCURA_MAX_MEMORY=-5: usage error naming the variable" -- env OBSCURA_MAX_MEMORY=-5 "$OBSCURA" ao "$R" --backend cpu -o "$T/x.exr"
said "ao: OBSCURA_MAX_MEMORY: '-5' is not a whole number of MiB"
ln -s "$PWD/$R" "$T/in.0001.exr"
expect 0 "obscura batch takes --max-memory" -- "$OBSCURA" batch "$T/in.####.exr" --frames 1 -o "$T/b.####.exr" \
    --camera "$CAMJ" --backend cpu --max-memory 1
check "batch --max-memory 1: the frame in bands (the warning), the whole frame's file" \
    "grep -q 'warning: --max-memory 1 MiB: the AO' '$T/err' && cmp -s '$T/default.whole.exr' '$T/b.0001.exr'"
check "help: ao lists --max-memory, info takes it" \
    "'$OBSCURA' ao --help | grep -q -- '--max-memory MIB' && '$OBSCURA' info --backend cpu --max-memory 64 | grep -q '^memory budget (CPU device): 64 MiB (--max-memory)'"

# obscurad --max-memory: its CPU worker runs the frame in bands in memory
# (obs_run_cpu_opts), the same bytes as without a budget; the flag over
# OBSCURA_MAX_MEMORY, the budget in the start log, bad values refused
W2C=$(tr -d ' \n' < "$CAMJ" |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
CAM="fov_y=50&near=0.05&far=100&world_to_camera=$W2C&format=exr&float=1"
start whole --backend cpu
OBSCURA_MAX_MEMORY=5000 start tiny --backend cpu --max-memory 1 --log-level debug
c0=$(post "$PORT_whole" "$CAM" "$R" "$T/d_whole.exr")
c1=$(post "$PORT_tiny" "$CAM" "$R" "$T/d_tiny.exr")
check "obscurad --max-memory 1: HTTP $c1, the AO bytes of a daemon without a budget (HTTP $c0)" \
    "[ '$c0' = 200 ] && [ '$c1' = 200 ] && cmp -s '$T/d_whole.exr' '$T/d_tiny.exr'"
check "obscurad --max-memory 1 over OBSCURA_MAX_MEMORY: the start log says it, the frame ran in bands" \
    "grep -q 'memory budget of a frame on the CPU device: 1 MiB (--max-memory)' '$T/tiny.log' && grep -q 'band 3: rows' '$T/tiny.log'"
check "obscurad: the band over the budget is a warning naming the option" \
    "grep -q \"warn: --max-memory 1 MiB: the AO's samples reach\" '$T/tiny.log'"
c2=$(post "$PORT_tiny" "$CAM" "$R" "$T/d_tiny2.exr")
check "obscurad: the same frame again (HTTP $c2): the warning once, then at debug level" \
    "[ \$(grep -c \"warn: --max-memory 1 MiB: the AO's samples reach\" '$T/tiny.log') = 1 ] && grep -q 'debug: --max-memory 1 MiB: .*(again)' '$T/tiny.log'"
check "obscurad without a budget: the start log says the default" \
    "grep -q 'memory budget of a frame on the CPU device: [0-9]* MiB (default: a quarter of' '$T/whole.log'"
expect 0 "obscura ao --server with --max-memory: the frame on obscurad" -- "$OBSCURA" ao "$R" --camera "$CAMJ" \
    --server "http://127.0.0.1:$PORT_whole" --max-memory 1 -o "$T/remote.exr"
said "the frame runs on obscurad, whose own --max-memory applies"
kill "$PID_whole" "$PID_tiny" 2>/dev/null
wait "$PID_whole" "$PID_tiny" 2>/dev/null
expect 2 "obscurad --max-memory abc: refused" -- "$OBSCURAD" --http 127.0.0.1:0 --backend cpu --max-memory abc
said "option max_memory: 'abc' is not a number"
expect 2 "obscurad --max-memory over the usable memory: refused" -- "$OBSCURAD" --http 127.0.0.1:0 --backend cpu --max-memory 999999999
said "max_memory: 999999999 MiB is more than the usable memory"
expect 2 "obscurad OBSCURA_MAX_MEMORY=0: refused" -- env OBSCURA_MAX_MEMORY=0 "$OBSCURAD" --http 127.0.0.1:0 --backend cpu
said "OBSCURA_MAX_MEMORY: '0' is not a budget"

# PNG output and deep input: whole, said
OBSCURA_BAND_ROWS=24 "$OBSCURA" ao "$R" --camera "$CAMJ" --backend cpu -v -o "$T/ao.png" 2>"$T/png.log"
rc=$?
check "PNG output: exit $rc, the frame read whole" "[ $rc -eq 0 ] && ! grep -q 'by rows' '$T/png.log'"
OBSCURA_BAND_ROWS=24 "$OBSCURA" ao "$DATA/deep_small.exr" --radius 0.6 --backend cpu -v -o "$T/deep.exr" 2>"$T/deep.log"
rc=$?
check "deep input: exit $rc, run whole and said" "[ $rc -eq 0 ] && grep -q 'deep input is read and run whole' '$T/deep.log'"
expect 0 "OBSCURA_BAND_ROWS=abc: left out with a warning" -- env OBSCURA_BAND_ROWS=abc "$OBSCURA" ao "$R" --camera "$CAMJ" --backend cpu -o "$T/abc.exr"
said "OBSCURA_BAND_ROWS=abc is not a positive count"
echo "e2e bands: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
