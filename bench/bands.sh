#!/bin/sh
# A frame by rows against the frame whole (README "Frames larger than
# memory"): `obscura ao --backend cpu` on the first scene upscaled to
# SIZE (default 3840x2160), whole, then by rows under OBSCURA_MAX_MEMORY
# MiB (default 256): peak RSS (/usr/bin/time -v), wall time and their
# ratios in one run, the bands, and whether the two files are the same
# bytes.  bench/RESULTS.md, "An 8K frame by rows", has the 8K run.
#
#   BUILD=build bench/bands.sh SCENE.exr CAMERA.json [SIZE [MIB]]
set -eu
BUILD=${BUILD:-build}
IN=$1 CAM=$2 SIZE=${3:-3840x2160} MIB=${4:-256}
TIME=/usr/bin/time
[ -x "$TIME" ] || { echo "bench bands: $TIME not found (apt-get install time); skipped" >&2; exit 0; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$BUILD/exr_upscale" "$IN" "$SIZE" "$TMP/in.exr" "$CAM" >/dev/null
unset OBSCURA_BAND_ROWS OBSCURA_MAX_MEMORY
run() { # NAME [ENV=VALUE]: peak kB and wall seconds into $TMP/NAME.*
    name=$1; shift
    env "$@" "$TIME" -f '%M %e' -o "$TMP/$name.time" "$BUILD/obscura" ao "$TMP/in.exr" --backend cpu -v \
        -o "$TMP/$name.exr" 2>"$TMP/$name.log"
}
run whole
run rows OBSCURA_MAX_MEMORY="$MIB"
read wk ws < "$TMP/whole.time"
read rk rs < "$TMP/rows.time"
bands=$(grep -c 'info: band [0-9]*: rows' "$TMP/rows.log" || true)
same=$(cmp -s "$TMP/whole.exr" "$TMP/rows.exr" && echo "the same bytes" || echo "DIFFERENT files")
echo "### A frame by rows: $SIZE, OBSCURA_MAX_MEMORY=$MIB (loaded machine: ratios from one run)"
echo
echo "| run | peak RSS (MiB) | wall (s) |"
echo "|---|---|---|"
echo "| whole | $((wk / 1024)) | $ws |"
echo "| by rows, $bands bands | $((rk / 1024)) | $rs |"
awk -v wk="$wk" -v rk="$rk" -v ws="$ws" -v rs="$rs" -v same="$same" 'BEGIN {
    printf "\nby rows / whole: peak RSS %.2f, wall %.2f; %s\n", rk / wk, rs / ws, same }'
grep -m1 'samples reach' "$TMP/rows.log" | sed 's/^obscura: warning: /note: /' || true
