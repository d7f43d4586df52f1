#!/bin/sh
# End-to-end tests of a frame by rows on the CPU device (obscura ao, README
# "Frames larger than memory"): with OBSCURA_BAND_ROWS (or a frame over
# OBSCURA_MAX_MEMORY) a flat EXR is read by rows, run in bands and written
# by rows, and the output file is the whole frame's, byte for byte (AO,
# composite as float with PIZ, half resolution, another method); outputs the rows path does not write (PNG)
# and deep input run whole, as before.
#
#   OBSCURA=build/obscura tests/e2e/bands.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
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
