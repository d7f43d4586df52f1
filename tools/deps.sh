#!/bin/sh
# Installs the Debian packages obscura's build and tests need, when any is
# missing.  As root: apt-get.  Otherwise: prints the exact command.
set -eu

PKGS="build-essential pkg-config libegl-dev libgl-dev libegl-mesa0 libosmesa6-dev \
libopenexr-dev libpng-dev libcjson-dev libcmocka-dev zlib1g-dev libmicrohttpd-dev curl \
libassimp-dev libembree-dev nettle-dev libsuitesparse-dev libmeshoptimizer-dev"
# Only for the tests: the preview page in a real browser (Chromium; node
# and npm fetch playwright-core), the deploy checks (systemd-analyze,
# PyYAML), make quality's referee (shared/tools/aometrics.py: numpy,
# OpenImageIO), oiiotool (tests/e2e/output.sh reads obscura's EXRs back with
# OpenImageIO), python3 with pip and wheel (the Python client's tests,
# pip install clients/python offline), Highway (make bench's blur kernel
# in Highway against the library's OpenMP simd form, bench/blur_hwy.cc).
# `deps.sh --build` leaves them out (deploy/container).
# `deps.sh --quality` adds what only make quality-masks needs: Blender
# (Cycles renders the hidden-object reference, tools/blender_masks.py) and
# sweethome3d-furniture (the CC0 meshes of the Blender room).  Neither the
# build, make demo nor make test needs them.
# `deps.sh --fuzz` adds clang and its runtime libraries (libFuzzer, the
# sanitizers): make test-long replays the fuzz targets' seeds with them
# (tests/e2e/fuzz.sh; make test's run of it skips without clang).
if [ "${1:-}" = "--quality" ]; then
    PKGS="$PKGS blender sweethome3d-furniture"
fi
if [ "${1:-}" = "--fuzz" ]; then
    PKGS="$PKGS clang libclang-rt-dev"
fi
if [ "${1:-}" != "--build" ]; then
    PKGS="$PKGS libhwy-dev chromium nodejs python3-yaml systemd python3-numpy python3-openimageio openimageio-tools python3 python3-pip python3-wheel"
    command -v npm >/dev/null 2>&1 || PKGS="$PKGS npm"
fi

missing=""
for p in $PKGS; do
    st=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
    case "$st" in
        *"install ok installed"*) ;;
        *) missing="$missing $p" ;;
    esac
done

[ -z "$missing" ] && exit 0

echo "deps: missing Debian packages:$missing"
if [ "$(id -u)" -eq 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -q
    # shellcheck disable=SC2086
    apt-get install -y -q --no-install-recommends $missing
else
    echo "deps: run as root:  apt-get install -y$missing" >&2
    exit 1
fi
