#!/bin/sh
# End-to-end tests of the obscura CLI: drives the real binary on real
# G-buffers and checks its files, messages and exit codes.
#
#   OBSCURA=build/obscura tests/e2e/run.sh
#
# Uses tests/data always, and ../shared/data (OBSCURA_SHARED_DATA) when it
# exists.  Prints one line per check; exits 1 if any check failed.
set -u
OBSCURA=${OBSCURA:-build/obscura}
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
DATA=tests/data
. tests/e2e/lib/common.sh

# value of KEY in the JSON line of the last compare
json() { sed -n "s/.*\"$1\": \([-0-9.e+]*\).*/\1/p" "$T/out"; }

# AO of SCENE (stem) against the Cycles AO pass in the same file;
# correlation must exceed 0.6, and the MSE MAX_MSE when given.
fidelity() {
    stem=$1; name=$(basename "$stem"); max_mse=${2:-}
    expect 0 "ao $name" -- "$OBSCURA" ao "$stem.exr" --camera "$stem.camera.json" -o "$T/$name.exr"
    expect 0 "ao $name as PNG" -- "$OBSCURA" ao "$stem.exr" --camera "$stem.camera.json" -o "$T/$name.png" -q
    expect 0 "compare $name" -- "$OBSCURA" compare "$stem.exr" "$T/$name.exr" \
        --channel-a ViewLayer.AO.R --channel-b AO.Y --json
    corr=$(json corr); mse=$(json mse); ssim=$(json ssim)
    echo "       $name vs Cycles AO: corr $corr, MSE $mse, SSIM $ssim"
    if awk "BEGIN { exit !($corr > 0.6) }"; then ok "$name correlation $corr > 0.6"; else
        bad "$name correlation $corr <= 0.6"; fi
    if [ -n "$max_mse" ]; then
        if awk "BEGIN { exit !($mse < $max_mse) }"; then ok "$name MSE $mse < $max_mse"; else
            bad "$name MSE $mse >= $max_mse"; fi
    fi
    mkdir -p out/e2e 2>/dev/null && cp "$T/$name.png" "out/e2e/${name}_ao.png" 2>/dev/null
}

echo "e2e: $OBSCURA"

echo "-- info and usage"
expect 0 "info" -- "$OBSCURA" info
if [ "$CPU_DEVICE" = 1 ]; then
    said "backend: cpu (the chain on the CPU device"
    said "^threads: "
else
    said "GL renderer"
fi
for b in egl-surfaceless osmesa; do
    expect 0 "info --backend $b" -- "$OBSCURA" info --backend $b
    said "backend: $b"
done
# egl-device needs a real GPU: it works, or says why not (exit 1)
"$OBSCURA" info --backend egl-device >"$T/out" 2>"$T/err"
case $? in
    0) ok "egl-device: $(grep renderer "$T/out")" ;;
    1) if grep -q "egl-device" "$T/err"; then ok "egl-device unavailable, said why: $(cat "$T/err")"; else bad "egl-device failed silently"; fi ;;
    *) bad "egl-device crashed" ;;
esac
OBSCURA_BACKEND=osmesa expect 0 "OBSCURA_BACKEND=osmesa" -- "$OBSCURA" info
said "backend: osmesa"
expect 2 "unknown backend" -- "$OBSCURA" info --backend vulkan
said "not one of"
expect 0 "help" -- "$OBSCURA" help
said "--radius"
expect 2 "no arguments" -- "$OBSCURA"
expect 2 "unknown command" -- "$OBSCURA" frobnicate
expect 2 "no output file" -- "$OBSCURA" ao "$DATA/room_small.exr"
said "no output file"
expect 2 "parameter out of range" -- "$OBSCURA" ao "$DATA/room_small.exr" -o "$T/x.exr" --samples 64
said "samples"
expect 2 "unknown option" -- "$OBSCURA" ao "$DATA/room_small.exr" -o "$T/x.exr" --no-such-flag 1
expect 2 "unknown output format" -- "$OBSCURA" ao "$DATA/room_small.exr" -o "$T/x.tif"

echo "-- fidelity against the Cycles AO pass (small scenes, tests/data)"
fidelity "$DATA/room_small"
fidelity "$DATA/yard_small"
if [ -d "$SHARED/blender" ]; then
    echo "-- fidelity, full-size scenes ($SHARED/blender)"
    # the defaults against EEVEE's GTAO on the same scenes (Blender 3.4,
    # distance 0.5 m): MSE 0.0074 on room, 0.0087 on yard (bench/QUALITY.md)
    fidelity "$SHARED/blender/room" 0.0074
    fidelity "$SHARED/blender/yard" 0.0087
else
    echo "  skip full-size scenes: $SHARED/blender not found"
fi

echo "-- outputs"
R="$DATA/room_small.exr"
C="$DATA/room_small.camera.json"
expect 0 "both to EXR" -- "$OBSCURA" ao "$R" --camera "$C" --output both -o "$T/both.exr" --float
expect 0 "EXR has AO.Y and RGBA" -- "$OBSCURA" compare "$T/both.exr" "$T/both.exr" --channel-a AO.Y --channel-b R --mask none
expect 0 "composite PNG 16-bit" -- "$OBSCURA" ao "$R" --camera "$C" --output composite --png-bits 16 -o "$T/c16.png"
expect 0 "both to PNG" -- "$OBSCURA" ao "$R" --camera "$C" --output both -o "$T/pair.png"
if [ -s "$T/pair.ao.png" ] && [ -s "$T/pair.composite.png" ]; then ok "both to PNG wrote two files"; else bad "both to PNG files missing"; fi
# the per-pixel sample count of adaptive sampling (VAO++ 4.1), a debug output
expect 0 "AO and sample count to EXR" -- "$OBSCURA" ao "$R" --camera "$C" --output ao,samples -o "$T/count.exr" --adaptive-diameter 0.04
expect 0 "EXR has AO.Y and Samples.Y" -- "$OBSCURA" compare "$T/count.exr" "$T/count.exr" --channel-a AO.Y --channel-b Samples.Y --mask none
expect 0 "sample count to PNG with the AO" -- "$OBSCURA" ao "$R" --camera "$C" --output ao,samples -o "$T/count.png"
if [ -s "$T/count.ao.png" ] && [ -s "$T/count.samples.png" ]; then ok "ao,samples to PNG wrote two files"; else bad "ao,samples PNG files missing"; fi
# the GL frames against the CPU twin: on the CPU device (OBSCURA_BACKEND=cpu)
# a GL backend named, so that GL is still what is compared
GLB=""
[ "$CPU_DEVICE" = 1 ] && GLB="--backend egl-surfaceless"
# the culling mask (VAO++ 4.2) and the colour-bleed term (4.7), GL and CPU twin
# shellcheck disable=SC2086
expect 0 "culling mask and bleed to EXR" -- "$OBSCURA" ao "$R" --camera "$C" --output ao,cull,bleed --bleeding full -o "$T/cb.exr" --float $GLB
expect 0 "culling mask and bleed, CPU twin" -- "$OBSCURA" ao "$R" --camera "$C" --output ao,cull,bleed --bleeding full -o "$T/cb_cpu.exr" --float --cpu
for ch in Cull.Y Bleed.G; do
    expect 0 "$ch: GL vs CPU twin" -- "$OBSCURA" compare "$T/cb_cpu.exr" "$T/cb.exr" --channel-a $ch --channel-b $ch --mask none --json
    mae=$(json mae)
    if awk "BEGIN { exit !($mae < 1e-4) }"; then ok "$ch GL vs CPU MAE $mae"; else bad "$ch GL vs CPU MAE $mae"; fi
done
expect 0 "cull mask to PNG with the AO" -- "$OBSCURA" ao "$R" --camera "$C" --output ao,cull -o "$T/cm.png"
if [ -s "$T/cm.ao.png" ] && [ -s "$T/cm.cull.png" ]; then ok "ao,cull to PNG wrote two files"; else bad "ao,cull PNG files missing"; fi
expect 2 "unknown output" -- "$OBSCURA" ao "$R" --camera "$C" --output ao,depth -o "$T/x.exr"
said "not one of ao|composite|both|samples"
expect 0 "CPU twin" -- "$OBSCURA" ao "$R" --camera "$C" --cpu -o "$T/cpu.exr" --float
# shellcheck disable=SC2086
expect 0 "GL float${GLB:+ ($GLB)}" -- "$OBSCURA" ao "$R" --camera "$C" -o "$T/gl.exr" --float $GLB
expect 0 "compare GL with CPU twin" -- "$OBSCURA" compare "$T/cpu.exr" "$T/gl.exr" --mask none --json
mae=$(json mae)
if awk "BEGIN { exit !($mae < 0.001) }"; then ok "GL vs CPU MAE $mae < 1e-3"; else bad "GL vs CPU MAE $mae"; fi
expect 0 "osmesa backend" -- "$OBSCURA" ao "$R" --camera "$C" --backend osmesa -o "$T/osm.exr" --float
expect 0 "compare osmesa with egl" -- "$OBSCURA" compare "$T/gl.exr" "$T/osm.exr" --mask none --json
mae=$(json mae)
if awk "BEGIN { exit !($mae < 1e-5) }"; then ok "osmesa vs egl-surfaceless MAE $mae < 1e-5"; else bad "osmesa vs egl MAE $mae"; fi

echo "-- cameras and channel maps"
expect 0 "preset + fov only (normals reconstructed)" -- "$OBSCURA" ao "$R" --preset blender --fov-y 50 -o "$T/fov.png" --output composite
said "reconstructing normals"
expect 3 "no camera at all (its position pass not solved)" -- "$OBSCURA" ao "$R" -o "$T/x.exr" --solve-camera=0
said "--fov-y"
expect 0 "explicit channels" -- "$OBSCURA" ao "$R" --camera "$C" --depth ViewLayer.Depth.Z \
    --normal ViewLayer.Normal.X,ViewLayer.Normal.Y,ViewLayer.Normal.Z --color ViewLayer.Combined.R,ViewLayer.Combined.G,ViewLayer.Combined.B -o "$T/x.exr"
expect 3 "missing channel named" -- "$OBSCURA" ao "$R" --camera "$C" --depth Nope.Z -o "$T/x.exr"
said "Nope.Z"
expect 3 "generic preset on a Blender file" -- "$OBSCURA" ao "$R" --camera "$C" --preset generic -o "$T/x.exr"
expect 3 "size limit" -- "$OBSCURA" ao "$R" --camera "$C" --max-size 100 -o "$T/x.exr"
said "limit"
expect 3 "missing input" -- "$OBSCURA" ao "$T/nope.exr" --camera "$C" -o "$T/x.exr"
expect 1 "unwritable output" -- "$OBSCURA" ao "$R" --camera "$C" -o "$T/no/such/dir/x.exr"
expect 3 "not an EXR" -- "$OBSCURA" ao "$C" --camera "$C" -o "$T/x.exr"
printf '{"width": 3}' > "$T/badcam.json"
expect 3 "bad camera JSON" -- "$OBSCURA" ao "$R" --camera "$T/badcam.json" -o "$T/x.exr"

echo "-- damaged EXRs: a clear error, never a crash"
n=0; crashed=0
for f in "$DATA"/damaged/* ; do
    case "$f" in *.rst) continue ;; esac
    n=$((n + 1))
    "$OBSCURA" ao "$f" --fov-y 50 -o "$T/d.exr" >"$T/out" 2>"$T/err"
    rc=$?
    if [ "$rc" -ne 3 ] && [ "$rc" -ne 0 ]; then
        crashed=$((crashed + 1)); echo "       $f: exit $rc"; tail -3 "$T/err"
    fi
done
if [ "$crashed" -eq 0 ]; then ok "$n damaged files: each rejected with exit 3 (or read)"; else bad "$crashed of $n damaged files crashed"; fi

echo "e2e: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
