#!/bin/sh
# Packs what bench/gpu.sh runs into one folder, for a GPU machine that has
# the driver but none of obscura's build dependencies (no compiler, no
# OpenEXR, assimp, Embree, glvnd ...): builds here, then copies
#
#   DIR/build/    obscura, extensions_bench, exr_upscale and the unit-test
#                 binaries (tests/unit/*/test_*.c), at the paths they have
#                 under build/, stripped
#   DIR/lib/      the shared libraries they need, found by following each
#                 binary's DT_NEEDED (readelf -d), less the C and C++
#                 runtimes; glvnd's libEGL/libOpenGL/libGLdispatch from
#                 Debian's debs (the GPU's driver brings only its vendor
#                 library, libEGL_nvidia); libOSMesa as a stub (see below)
#   DIR/libc/     the C and C++ runtimes and the loader, used only when the
#                 machine's glibc is older than this one's (bench/gpu_run.sh)
#   DIR/bench/    gpu.sh, gpu_run.sh and coldstart.sh, for a checkout that
#                 lacks these versions (run sh DIR/bench/gpu_run.sh)
#   DIR/data/     room and yard (.obj, .camera.json, .exr) from
#                 ../shared/data/blender: the G-buffers of gpu.sh's tables,
#                 and the unit tests that compare against Blender's passes
#                 (they skip without room.obj, and fail without the rest)
#
# and all of that but bench/ again as DIR/pack.tar.xz (one solid archive: the binaries
# share libobscura's code, so it packs to a fraction of the folder; when the
# folder is too large to travel, send DIR/pack.tar.xz alone and
# bench/gpu_run.sh unpacks it there).  Mesa itself
# is not packed: libOSMesa.so.8 (and through it libLLVM, over 100 MB) is
# replaced by a stub whose entry points fail, so the osmesa backend reports
# itself unavailable and the EGL backends are the ones that run.
#
#   bench/gpu_pack.sh [DIR]        DIR defaults to .gpu
#   GPU_PACK_DEBS=FOLDER           where the glvnd debs are (else downloaded
#                                  with apt-get download into
#                                  /tmp/gpu_pack_debs)
#   GPU_PACK_UNITS=0               no unit-test binaries
set -eu
DIR=${1:-.gpu}
JOBS=${JOBS:-2}
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
UNITS=""
if [ "${GPU_PACK_UNITS:-1}" = 1 ]; then
    UNITS=$(ls tests/unit/*/test_*.c | sed 's|^tests/unit/\(.*\)\.c$|build/tests/\1|')
fi
BINS="build/obscura build/extensions_bench build/exr_upscale"

# shellcheck disable=SC2086
make -j"$JOBS" all build/extensions_bench build/exr_upscale $UNITS

rm -rf "$DIR"
mkdir -p "$DIR/build" "$DIR/lib" "$DIR/libc" "$DIR/data/blender"
for b in $BINS $UNITS; do
    mkdir -p "$DIR/$(dirname "$b")"
    strip --strip-unneeded -o "$DIR/$b" "$b"
done

# ---- the shared libraries ---------------------------------------------------
# the C/C++ runtimes every Linux has (copied to libc/ only), glvnd's own (from
# the debs below) and OSMesa (a stub): not followed
runtime='^(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|librt|libutil|ld-linux-x86-64)\.so'
skip='^(libEGL|libGLdispatch|libOpenGL|libGL|libGLX|libGLESv2|libOSMesa)\.so'
path_of() { # NAME: the file the loader would take here
    ldconfig -p | awk -v n="$1" '$1 == n && /x86-64/ {print $NF; exit}'
}
todo=$(for b in $BINS $UNITS; do readelf -d "$b" | sed -n 's/.*NEEDED.*\[\(.*\)\]/\1/p'; done | sort -u)
done_=" "
while [ -n "$todo" ]; do
    next=""
    for n in $todo; do
        case "$done_" in *" $n "*) continue ;; esac
        done_="$done_$n "
        if echo "$n" | grep -Eq "$runtime|$skip"; then continue; fi
        p=$(path_of "$n")
        [ -n "$p" ] || { echo "gpu_pack: $n not found here" >&2; exit 1; }
        cp -L "$p" "$DIR/lib/$n"
        next="$next $(readelf -d "$p" | sed -n 's/.*NEEDED.*\[\(.*\)\]/\1/p')"
    done
    todo=$next
done
for n in libc.so.6 libm.so.6 libstdc++.so.6 libgcc_s.so.1 libpthread.so.0 libdl.so.2 librt.so.1 \
    ld-linux-x86-64.so.2; do
    cp -L "$(path_of "$n")" "$DIR/libc/$n"
done

# glvnd from Debian's debs: the driver's libEGL_nvidia plugs into it
DEBS=${GPU_PACK_DEBS:-/tmp/gpu_pack_debs}
if ! ls "$DEBS"/libegl1_*.deb > /dev/null 2>&1; then
    mkdir -p "$DEBS" /tmp/gpu_pack_apt/partial
    o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/gpu_pack_apt'
    # shellcheck disable=SC2086
    apt-get $o update > /dev/null
    # shellcheck disable=SC2086
    (cd "$DEBS" && apt-get $o download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
fi
x=$(mktemp -d)
for f in "$DEBS"/*.deb; do dpkg -x "$f" "$x"; done
cp -L "$x"/usr/lib/x86_64-linux-gnu/lib*.so.[0-9] "$DIR/lib/"
rm -rf "$x"

# OSMesa as a stub: every entry point obscura calls fails (core/gl/osmesa.c)
cat > "$DIR/osmesa_stub.c" << 'EOF'
#include <stddef.h>
void *OSMesaGetProcAddress(const char *n) { (void)n; return NULL; }
void *OSMesaCreateContextAttribs(const int *a, void *s) { (void)a; (void)s; return NULL; }
void OSMesaDestroyContext(void *c) { (void)c; }
unsigned char OSMesaMakeCurrent(void *c, void *b, int t, int w, int h)
{ (void)c; (void)b; (void)t; (void)w; (void)h; return 0; }
void *OSMesaGetCurrentContext(void) { return NULL; }
EOF
missing=$(nm -D --undefined-only $BINS $UNITS 2>/dev/null | awk '/ OSMesa/ {print $2}' | sort -u |
    while read -r s; do grep -q "$s(" "$DIR/osmesa_stub.c" || echo "$s"; done)
[ -z "$missing" ] || { echo "gpu_pack: the OSMesa stub lacks: $missing" >&2; exit 1; }
cc -shared -fPIC -O2 -Wl,-soname,libOSMesa.so.8 -o "$DIR/lib/libOSMesa.so.8" "$DIR/osmesa_stub.c"
rm "$DIR/osmesa_stub.c"
strip --strip-unneeded "$DIR"/lib/*.so* 2> /dev/null || true

# ---- data -------------------------------------------------------------------
for f in room.obj room.camera.json room.exr yard.obj yard.camera.json yard.exr; do
    [ -f "$SHARED/blender/$f" ] && cp "$SHARED/blender/$f" "$DIR/data/blender/"
done

mkdir -p "$DIR/bench"
cp bench/gpu.sh bench/gpu_run.sh bench/coldstart.sh "$DIR/bench/"
tar -C "$DIR" -cf - build lib libc data | xz -9 -T"$JOBS" > "$DIR/pack.tar.xz"
echo "gpu_pack: $DIR $(du -sh --exclude=pack.tar.xz "$DIR" | cut -f1)," \
    "$DIR/pack.tar.xz $(du -h "$DIR/pack.tar.xz" | cut -f1)"
