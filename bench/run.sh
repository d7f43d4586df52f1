#!/bin/sh
# make bench: frame timings on this machine.  Reads the full-size scenes
# from ../shared/data when present, else the small copies in tests/data.
set -eu
BUILD=${BUILD:-build}
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
if [ -d "$SHARED/blender" ]; then
    set -- "$SHARED/blender/room.exr" "$SHARED/blender/room.camera.json" \
           "$SHARED/blender/yard.exr" "$SHARED/blender/yard.camera.json"
else
    echo "bench: $SHARED/blender not found; using the small scenes in tests/data" >&2
    set -- tests/data/room_small.exr tests/data/room_small.camera.json \
           tests/data/yard_small.exr tests/data/yard_small.camera.json
fi
echo "## $(date -u +%Y-%m-%d) $(uname -m), $(nproc) cores"
echo
"$BUILD/frame_bench" "$@"
echo
# --quality's presets side by side at 1920x1080 and 3840x2160 (the first
# scene upscaled): wall and GL time and the ratio to default's in the same
# run, then a table of each pass's GL time per preset
"$BUILD/frame_bench" --frames 5 --presets "$1" "$2"
echo
# the CPU device against the GL context, every method at 1920x1080 and
# 3840x2160 (the first scene upscaled): wall ms and the ratio cpu / GL in
# the same run, then the CPU device's time per pass
"$BUILD/frame_bench" --frames 5 --devices "$1" "$2"
echo
# the blur kernel in Highway against the library's OpenMP simd form, one
# thread (bench/blur_hwy.cc; when libhwy-dev is installed)
if [ -x "$BUILD/blur_hwy_bench" ]; then
    "$BUILD/blur_hwy_bench"
    echo
fi
# the same for ao_definition rays' conversion (bench/rays_hwy.cc)
if [ -x "$BUILD/rays_hwy_bench" ]; then
    "$BUILD/rays_hwy_bench"
    echo
fi
# cold start: one process with obscura's program cache warm and Mesa's
# off, against Mesa's cache warm and no cache (bench/coldstart.sh)
BUILD="$BUILD" bench/coldstart.sh
echo
# VAO++ Table 1: the extensions at 2..32 samples, 1080p and 4K, GL timer
# queries (bench/extensions_bench.c).  G-buffers rendered at those sizes
# from the scene's mesh (obscura gbuffer, same camera, same vertical field
# of view) when it is there, else the first G-buffer scaled.
OBJ=${1%.exr}.obj
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
if [ -f "$OBJ" ]; then
    for size in 1920x1080 3840x2160; do
        "$BUILD/obscura" gbuffer "$OBJ" --camera "$2" --width "${size%x*}" --height "${size#*x}" \
            -o "$TMP/$size.exr" -q
        "$BUILD/extensions_bench" --sizes "$size" "$TMP/$size.exr"
        echo
    done
    # VAO++ Table 2: the other methods of --method at matching levels, 1080p
    "$BUILD/extensions_bench" --methods --sizes 1920x1080 "$TMP/1920x1080.exr"
else
    "$BUILD/extensions_bench" "$1" "$2"
    echo
    "$BUILD/extensions_bench" --methods --sizes 1920x1080 "$1" "$2"
fi
echo
# a frame by rows against the frame whole on the CPU device: peak RSS
# and wall time (bench/bands.sh; 3840x2160, a 256 MiB budget)
BUILD="$BUILD" bench/bands.sh "$1" "$2"
echo
# the daemon: round trip vs in-process, concurrent clients (1920x1080)
BUILD="$BUILD" bench/daemon_bench.sh "$1" "$2"
echo
# OITAO Table I: deep input's list compression, m = 2, 4, 8 against the
# uncompressed lists (bench/deep_bench.c), on OpenEXR's LowResLeftView deep
# images when present; the AO PNGs go to bench/deep/.
DEEP=$SHARED/openexr-images/v2/LowResLeftView
if [ -f "$DEEP/Balls.exr" ]; then
    mkdir -p bench/deep
    "$BUILD/deep_bench" "$DEEP" bench/deep
else
    echo "bench: $DEEP not found; deep input (OITAO Table I) skipped" >&2
fi
