#!/bin/sh
# Checks of deploy/: the systemd unit (systemd-analyze verify), the
# example config (obscurad reads it), the Dockerfile (its run-time
# packages cover every library obscurad and obscura link; hadolint when
# installed; nothing links GL, and the CPU device runs with the GL
# libraries hidden), the Kubernetes manifests and farm job templates
# (tests/deploy/check_manifests.py, PyYAML; the bake templates' commands
# and bake-dynamic templates' commands run on the fixture level, merged =
# unsharded), and the plain farm script
# (runs a chunk in-process).  There is no container engine here: the
# image itself is not built.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/deploy.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
. tests/e2e/lib/common.sh

echo "e2e deploy: deploy/"
echo "-- systemd"
U=deploy/systemd/obscurad.service
check "unit: unprivileged user, ProtectSystem=strict, restart on failure, config in /etc/obscura" \
    "grep -q '^DynamicUser=yes' $U && grep -q '^ProtectSystem=strict' $U && grep -q '^Restart=on-failure' $U && grep -q -- '--config /etc/obscura/obscurad.conf' $U"
check "unit: CacheDirectory=obscura, passed as --cache-dir /var/cache/obscura" \
    "grep -q '^CacheDirectory=obscura\$' $U && grep -q '^ExecStart=.* --cache-dir /var/cache/obscura' $U"
if command -v systemd-analyze >/dev/null 2>&1; then
    # verify wants the ExecStart binary to exist: point it at this build
    # (OBSCURAD relative to here, or absolute)
    case "$OBSCURAD" in /*) abs=$OBSCURAD ;; *) abs=$(pwd)/$OBSCURAD ;; esac
    sed "s|/usr/local/bin/obscurad|$abs|" "$U" > "$T/obscurad.service"
    systemd-analyze verify --man=no "$T/obscurad.service" > "$T/verify" 2>&1
    rc=$?
    if [ $rc -ne 0 ] && grep -qi 'system has not been booted\|failed to connect\|permission denied' "$T/verify"; then
        skip "systemd-analyze verify cannot run here: $(head -1 "$T/verify")"
    else
        check "systemd-analyze verify: exit $rc, no warnings" "[ $rc -eq 0 ] && [ ! -s '$T/verify' ]"
        [ -s "$T/verify" ] && sed 's/^/       /' "$T/verify"
        sed 's/^Type=simple/Type=bogus/' "$T/obscurad.service" > "$T/bad.service"
        systemd-analyze verify --man=no "$T/bad.service" > "$T/verify2" 2>&1
        check "(and it does catch a bad unit)" "[ -s '$T/verify2' ]"
    fi
else
    skip "systemd-analyze not installed (make deps installs systemd)"
fi
"$OBSCURAD" --config deploy/systemd/obscurad.conf --help > "$T/help" 2>&1
check "obscurad reads deploy/systemd/obscurad.conf" "[ $? -eq 0 ]"

echo "-- container"
D=deploy/container/Dockerfile
check "Dockerfile: Debian 12, non-root, /healthz health check, NVIDIA graphics capability" \
    "grep -q '^FROM debian:12' $D && grep -q '^USER 10001' $D && grep -q '^HEALTHCHECK' $D && grep -q 'CMD curl.*/healthz' $D && grep -q 'NVIDIA_DRIVER_CAPABILITIES=graphics' $D"
# the warmup runs as the run-time user, after USER, into the folder the
# daemon reads (OBSCURA_CACHE_DIR), which that user owns
check "Dockerfile: obscura warmup --methods all at image build, as user 10001, into OBSCURA_CACHE_DIR" \
    "sed -n '/^USER 10001/,\$p' $D | grep -q '^RUN obscura warmup --methods all' && sed -n '/^USER 10001/,\$p' $D | grep -q '^ENV OBSCURA_CACHE_DIR=/var/cache/obscura' && grep -q 'install -d -o 10001 -g 10001 .*/var/cache/obscura' $D"
# what the image's build step runs works here: the same command into a
# fresh folder, then a frame on llvmpipe (the GL context the image's
# cache serves, whatever OBSCURA_BACKEND this run has) that compiles nothing
env -u OBSCURA_BACKEND "$OBSCURA" warmup --methods all --backend egl-surfaceless --cache-dir "$T/imgcache" -q \
    > "$T/warmup" 2>&1
wrc=$?
env -u OBSCURA_BACKEND "$OBSCURA" ao "$DATA/room_small.exr" --camera "$DATA/room_small.camera.json" -o "$T/warm.exr" -v \
    --backend egl-surfaceless --cache-dir "$T/imgcache" 2> "$T/warm.err"
check "the Dockerfile's warmup runs (exit $wrc); a frame after it compiles nothing" \
    "[ $wrc -eq 0 ] && grep -q 'programs: 0 compiled' '$T/warm.err'"
# every shared library the binaries need, by Debian package, is installed
# in the run-time stage (or is in every Debian base image)
runtime=$(sed -n '/^FROM debian:12-slim/,$p' "$D")
missing=""
for bin in "$OBSCURAD" "$OBSCURA"; do
    for lib in $(readelf -d "$bin" 2>/dev/null | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
        # the sanitizer runtimes of a `make test` ASan build are not shipped
        case "$lib" in libasan.so*|libubsan.so*|liblsan.so*|libtsan.so*) continue ;; esac
        path=$(ldconfig -p | sed -n "s/^[[:space:]]*$lib (.*x86-64.*) => \(.*\)/\1/p;s/^[[:space:]]*$lib (libc6,x86-64) => \(.*\)/\1/p" | head -1)
        [ -n "$path" ] || path=$(ldconfig -p | sed -n "s/^[[:space:]]*$lib .* => \(.*\)/\1/p" | head -1)
        pkg=$(dpkg -S "$(readlink -f "$path")" 2>/dev/null | head -1 | cut -d: -f1)
        [ -n "$pkg" ] || pkg=$(dpkg -S "$path" 2>/dev/null | head -1 | cut -d: -f1)
        case "$pkg" in libc6|libgcc-s1|libstdc++6) continue ;; esac # in every image
        prio=$(dpkg-query -W -f='${Priority}' "$pkg" 2>/dev/null)
        case "$prio" in required|important) continue ;; esac
        echo "$runtime" | grep -qw -- "$pkg" || missing="$missing $lib($pkg)"
    done
done
check "run-time stage installs the package of every linked library${missing:+ (missing:$missing)}" "[ -z '$missing' ]"
# a node without GL (the image's BACKEND=cpu): nothing links a GL library,
# and with libEGL and libOSMesa hidden (bound over by /dev/null in a mount
# namespace of this process's own) the CPU device still answers, and a GL
# backend says what to install
gl_linked=$(readelf -d "$OBSCURAD" "$OBSCURA" | grep -E 'NEEDED.*lib(EGL|OSMesa|GL|OpenGL|GLX)\b')
check "Dockerfile: BACKEND=cpu leaves the GL packages out; obscura and obscurad link no GL library${gl_linked:+ ($gl_linked)}" \
    "[ -z '$gl_linked' ] && grep -q 'if \[ \"\$BACKEND\" = cpu \]; then gl=\"\"' $D && grep -q 'OBSCURA_BACKEND=\$BACKEND' $D"
egl=$(ldconfig -p | sed -n 's/^[[:space:]]*libEGL\.so\.1 (libc6,x86-64) => //p' | head -1)
osm=$(ldconfig -p | sed -n 's/^[[:space:]]*libOSMesa\.so\.8 (libc6,x86-64) => //p' | head -1)
if [ "$(id -u)" = 0 ] && [ -n "$egl" ] && [ -n "$osm" ] && unshare -m true 2>/dev/null; then
    unshare -m sh -c 'mount --bind /dev/null "$(readlink -f "$1")" && mount --bind /dev/null "$(readlink -f "$2")" &&
        "$3" ao tests/data/room_small.exr --camera tests/data/room_small.camera.json --backend cpu -o "$4/nogl.exr" -q &&
        env -u OBSCURA_BACKEND OBSCURA_CACHE_DIR="$4/nogl-cache" "$3" ao tests/data/room_small.exr \
            --camera tests/data/room_small.camera.json -o "$4/nogl-default.exr" -q &&
        { "$3" info --backend egl-surfaceless > "$4/nogl.info" 2>&1; echo $? > "$4/nogl.rc"; }' \
        - "$egl" "$osm" "$OBSCURA" "$T" > "$T/nogl.err" 2>&1
    rc=$?
    check "without libEGL and libOSMesa: the CPU device runs (exit $rc); a GL backend exits 1 naming libegl1" \
        "[ $rc -eq 0 ] && [ -s '$T/nogl.exr' ] && [ \"\$(cat '$T/nogl.rc')\" = 1 ] && grep -q 'install libegl1' '$T/nogl.info'"
    check "without libEGL and libOSMesa, no backend named and nothing kept: the CPU device's frame, the same bytes" \
        "[ $rc -eq 0 ] && cmp -s '$T/nogl.exr' '$T/nogl-default.exr'"
    [ $rc -eq 0 ] || sed 's/^/       /' "$T/nogl.err" | tail -3
else
    skip "a node without GL libraries: needs root and unshare -m (a mount namespace to hide them)"
fi
if command -v hadolint >/dev/null 2>&1; then
    hadolint "$D" > "$T/hadolint" 2>&1
    check "hadolint" "[ $? -eq 0 ]"
else
    skip "hadolint not installed (not in Debian); README gives the build and run commands"
fi

echo "-- Kubernetes and farm templates"
PY=""
for p in /usr/bin/python3 python3; do
    if command -v "$p" >/dev/null 2>&1 && "$p" -c 'import yaml' 2>/dev/null; then PY=$p; break; fi
done
if [ -n "$PY" ]; then
    # the bake templates' commands run on the fixture level
    OBSCURA="$(cd "$(dirname "$OBSCURA")" && pwd)/$(basename "$OBSCURA")" \
        OBSCURA_BAKE_LEVEL="$(pwd)/$DATA/levels/aalborg_cut.acc" \
        "$PY" tests/deploy/check_manifests.py deploy > "$T/manifests" 2>&1
    rc=$?
    grep -v '^manifests: ' "$T/manifests"
    check "manifests: exit $rc" "[ $rc -eq 0 ]"
else
    skip "no python3 with PyYAML (make deps installs python3-yaml)"
fi

echo "-- the plain farm script"
mkdir -p "$T/shot"
for f in 1 2 3; do ln -s "$(pwd)/$DATA/room_small.exr" "$T/shot/g.000$f.exr"; done
OBSCURA="$OBSCURA" OBSCURA_INPUT="$T/shot/g.####.exr" OBSCURA_OUTPUT="$T/ao/ao.####.exr" \
    OBSCURA_CAMERA="$DATA/room_small.camera.json" OBSCURA_ARGS="--samples 4" \
    deploy/farm/obscura-chunk.sh 2 3 > "$T/chunk" 2>&1
rc=$?
check "obscura-chunk.sh 2 3: exit $rc, frames 2 and 3 written" "[ $rc -eq 0 ] && [ -s $T/ao/ao.0002.exr ] && [ -s $T/ao/ao.0003.exr ] && [ ! -e $T/ao/ao.0001.exr ]"
OBSCURA="$OBSCURA" OBSCURA_INPUT="$T/shot/g.####.exr" OBSCURA_OUTPUT="$T/ao/ao.####.exr" \
    OBSCURA_CAMERA="$DATA/room_small.camera.json" deploy/farm/obscura-chunk.sh 3 5 > "$T/chunk" 2>&1
rc=$?
check "a missing frame in the chunk: exit $rc (3: a frame missing, do not retry)" "[ $rc -eq 3 ]"
echo "e2e deploy: $pass passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
