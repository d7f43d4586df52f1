#!/bin/sh
# bench/gpu.sh on a GPU machine without obscura's build dependencies, from
# what bench/gpu_pack.sh packed: unpacks DIR/pack.tar.xz when the folder
# itself did not travel, finds the driver's EGL library and its glvnd
# vendor file, falls back to the packed C runtime when the machine's
# glibc is older than the one the binaries were built against, and runs
# GPU_SH_PREBUILT=DIR bench/gpu.sh (the gpu.sh beside this script).
#
#   OUT=DIR GPU_SH_BUDGET=S bench/gpu_run.sh [--check]
#   OUT=DIR GPU_SH_BUDGET=S sh .gpu/bench/gpu_run.sh   the copies packed
#                         with the binaries, for a checkout without them
#   GPU_PACK=DIR          the packed folder (default .gpu)
#   GPU_RUN_OWN_LIBC=1    use the packed C runtime even when not needed
#   GPU_RUN_BUNDLE=DIR    afterwards, OUT's text files (not the G-buffer
#                         EXRs) as DIR/results.tar.gz, and summary.txt
#                         beside it: for a tool that fetches a few files
#
# Writes OUT/env.txt (what was found and chosen); exits as gpu.sh does.
set -u
P=${GPU_PACK:-.gpu}
OUT=${OUT:-./gpu-results}
mkdir -p "$OUT" || exit 1
export OUT
E=$OUT/env.txt
: > "$E"
note() { echo "gpu_run: $*" | tee -a "$E"; }

if [ ! -e "$P/build/obscura" ]; then
    [ -f "$P/pack.tar.xz" ] || { note "no $P/build/obscura nor $P/pack.tar.xz: run bench/gpu_pack.sh"; exit 2; }
    if command -v xz > /dev/null 2>&1; then
        xz -dc "$P/pack.tar.xz" | tar -C "$P" -xf - build lib libc data
    else
        python3 -c 'import sys, tarfile; t = tarfile.open(sys.argv[1])
t.extractall(sys.argv[2], [m for m in t if m.name.split("/")[0] in ("build", "lib", "libc", "data")])' \
            "$P/pack.tar.xz" "$P"
    fi || { note "could not unpack $P/pack.tar.xz"; exit 2; }
    note "unpacked $P/pack.tar.xz"
fi
P=$(cd "$P" && pwd)

# the driver's EGL library: in the loader's cache, else in the driver's folder
if ! ldconfig -p 2> /dev/null | grep -q 'libEGL_nvidia\.so\.0'; then
    for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib64 /usr/lib/x86_64-linux-gnu; do
        if [ -e "$d/libEGL_nvidia.so.0" ]; then
            LD_LIBRARY_PATH="$d${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
            export LD_LIBRARY_PATH
            note "libEGL_nvidia.so.0 in $d (not in ldconfig's cache): on LD_LIBRARY_PATH"
            break
        fi
    done
fi
# the binaries need this machine's glibc to be at least the build's
err=$(LD_LIBRARY_PATH="$P/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$P/build/obscura" --version 2>&1 > /dev/null)
if [ "${GPU_RUN_OWN_LIBC:-0}" = 1 ] || echo "$err" | grep -q 'GLIBC'; then
    note "obscura --version: ${err:-(forced)}"
    note "running every packed binary through the packed loader and C runtime ($P/libc)"
    for f in $(find "$P/build" -type f | sort); do
        r="$P/real/${f#"$P"/build/}"
        mkdir -p "$(dirname "$r")"
        mv "$f" "$r"
        printf '#!/bin/sh\nexec "%s/libc/ld-linux-x86-64.so.2" --library-path "%s/libc:%s/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "%s" "$@"\n' \
            "$P" "$P" "$P" "$r" > "$f"
        chmod +x "$f"
    done
    "$P/build/obscura" --version > /dev/null 2>> "$E" || { note "still failing"; exit 2; }
fi

# glvnd's vendor file: the packed libEGL looks in /usr/share and /etc only,
# and a container may have the driver's file only in the driver's folder
# (/usr/local/nvidia/share/glvnd).  So: the first set-up that gives
# obscura an EGL device, of as found and each vendor file named in
# __EGL_VENDOR_LIBRARY_FILENAMES
probe() { # [VENDOR_FILE]
    env ${1:+__EGL_VENDOR_LIBRARY_FILENAMES="$1"} \
        LD_LIBRARY_PATH="$P/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
        "$P/build/obscura" info --backend egl-device > /dev/null 2>&1
}
if [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] && ! probe; then
    for f in /usr/local/nvidia/share/glvnd/egl_vendor.d/*.json /usr/share/glvnd/egl_vendor.d/*.json \
        /etc/glvnd/egl_vendor.d/*.json; do
        [ -f "$f" ] || continue
        { echo "$f:"; cat "$f"; } >> "$E" 2>&1
        if probe "$f"; then
            export __EGL_VENDOR_LIBRARY_FILENAMES="$f"
            note "an EGL device with __EGL_VENDOR_LIBRARY_FILENAMES=$f (none without it)"
            break
        fi
    done
    [ -n "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] || note "no vendor file gave obscura an EGL device"
fi

{
    echo "glibc: $(ldd --version 2> /dev/null | head -1)"
    echo "LD_LIBRARY_PATH=${LD_LIBRARY_PATH:-}"
    echo "__EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-}"
    ls /usr/share/glvnd/egl_vendor.d /etc/glvnd/egl_vendor.d 2>&1
    ldconfig -p 2> /dev/null | grep -E 'libEGL|libGLdispatch|libOpenGL|nvidia' | head -20
    echo "missing libraries of obscura:"
    LD_LIBRARY_PATH="$P/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" ldd "$P/build/obscura" 2>&1 |
        grep 'not found'
} >> "$E" 2>&1
# when the EGL device is not found: which libraries the loader tried
if ! LD_LIBRARY_PATH="$P/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
    "$P/build/obscura" info --backend egl-device > /dev/null 2>&1; then
    note "obscura info --backend egl-device failed; the loader's trace (LD_DEBUG=libs):"
    LD_LIBRARY_PATH="$P/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" LD_DEBUG=libs \
        "$P/build/obscura" info --backend egl-device 2>&1 |
        grep -iE 'egl|nvidia|GLdispatch|error|cannot' | grep -v 'search path' | tail -40 | tee -a "$E"
    # glvnd drops a vendor library's dlopen error: ask for it directly
    LD_LIBRARY_PATH="$P/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" python3 -c \
        'import ctypes; ctypes.CDLL("libEGL_nvidia.so.0"); print("libEGL_nvidia.so.0 loads")' 2>&1 |
        tail -2 | tee -a "$E"
fi

# gpu.sh beside this script: DIR/bench/ holds the copies gpu_pack.sh made,
# for a checkout whose own bench/gpu.sh predates GPU_SH_PREBUILT
GPU_SH_PREBUILT="$P" sh "$(dirname "$0")/gpu.sh" "$@"
rc=$?
if [ -n "${GPU_RUN_BUNDLE:-}" ]; then
    mkdir -p "$GPU_RUN_BUNDLE"
    tar -C "$OUT" -czf "$GPU_RUN_BUNDLE/results.tar.gz" --exclude='*.exr' .
    cp "$OUT/summary.txt" "$GPU_RUN_BUNDLE/" 2> /dev/null
fi
exit $rc
