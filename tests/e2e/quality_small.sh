#!/bin/sh
# Keeps the AO from sliding back on two scenes it was not developed on:
# the 320x240 copies in tests/data of two validation scenes of
# ../shared/data/blender/validation (dining at its AO distance 2 m,
# workshop at 0.25 m), each scene's distance passed as --radius and
# nothing else, scored against the Cycles AO pass in the same file
# (obscura compare, the metrics of shared/tools/aometrics.py).
#
#   OBSCURA=build/obscura tests/e2e/quality_small.sh
#
# The bounds are the MSE measured on this build (llvmpipe) times 1.02.
# Why 2 %: the spread between two conforming implementations of the same
# estimator, the GL pass and its CPU twin (--cpu), is at most 0.03 % of
# the MSE on these files, and the osmesa and EGL backends agree exactly,
# so a driver or compiler stays far inside 2 %; a change of the
# estimator that raises the error level by 2 % or more fails.  Measured
# (MSE / SSIM vs Cycles): default dining 0.017035 / 0.710, workshop
# 0.004168 / 0.903; --method gtao dining 0.007955 / 0.721, workshop
# 0.001930 / 0.936.
set -u
OBSCURA=${OBSCURA:-build/obscura}
DATA=tests/data
. tests/e2e/lib/common.sh

echo "e2e quality_small: $OBSCURA"

# value of KEY in the JSON line of $T/c.json
json() { sed -n "s/.*\"$1\": \([-0-9.e+]*\).*/\1/p" "$T/c.json"; }

# score SCENE RADIUS MEASURED NAME [PARAMS...]: MSE against Cycles below
# MEASURED * 1.02
score() {
    scene=$1 radius=$2 measured=$3 name=$4
    shift 4
    stem=$DATA/${scene}_small
    if ! "$OBSCURA" ao "$stem.exr" --camera "$stem.camera.json" --radius "$radius" "$@" --float \
        -o "$T/$scene.$name.exr" -q 2>"$T/err"; then
        bad "$scene ($name): ao failed: $(tail -n 1 "$T/err")"
        return
    fi
    if ! "$OBSCURA" compare "$stem.exr" "$T/$scene.$name.exr" --channel-a ViewLayer.AO.R \
        --channel-b AO.Y --json >"$T/c.json" 2>"$T/err"; then
        bad "$scene ($name): compare failed: $(tail -n 1 "$T/err")"
        return
    fi
    mse=$(json mse) ssim=$(json ssim)
    bound=$(awk -v m="$measured" 'BEGIN { printf "%.6f", m * 1.02 }')
    check "$scene at $radius m ($name): MSE $mse < $bound (measured $measured + 2 %), SSIM $ssim" \
        "awk -v a='$mse' -v b='$bound' 'BEGIN { exit !(a != \"\" && a + 0 < b + 0) }'"
}

score dining 2.0 0.017035 default
score workshop 0.25 0.004168 default
score dining 2.0 0.007955 gtao --method gtao
score workshop 0.25 0.001930 gtao --method gtao

echo "e2e quality_small: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
