#!/bin/sh
# The preview page in a real browser (tests/browser/preview.test.mjs):
# Debian's headless Chromium driven by playwright-core, against a real
# obscurad on a free loopback port.  Skipped, with a message, when
# Chromium or node is not installed (make deps installs both).
#
#   OBSCURAD=build/obscurad tests/e2e/browser.sh
#
# playwright-core comes from tests/browser/package-lock.json (npm ci, no
# browser download) into tests/browser/node_modules, kept between runs.
set -u
OBSCURAD=${OBSCURAD:-build/obscurad}
OBSCURA=${OBSCURA:-build/obscura}
DATA=tests/data
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
. tests/e2e/lib/common.sh

echo "e2e browser: $OBSCURAD"
if [ ! -x "$CHROMIUM" ] || ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    echo "  skip the browser test: needs $CHROMIUM, node and npm (make deps installs them)"
    echo "e2e browser: 0 passed, 0 failed, 1 skipped"
    exit 0
fi
B=tests/browser
if [ ! -f "$B/node_modules/playwright-core/package.json" ] ||
    ! grep -q "\"version\": \"$(sed -n 's/.*"playwright-core": "\(.*\)".*/\1/p' $B/package.json)\"" \
        "$B/node_modules/playwright-core/package.json"; then
    (cd "$B" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error) >"$T/npm.log" 2>&1
    if [ $? -ne 0 ]; then
        bad "npm ci in $B (playwright-core)"; tail -5 "$T/npm.log"
        echo "e2e browser: $pass passed, $failed failed"; exit 1
    fi
fi

W2C=$(tr -d ' \n' < "$DATA/room_small.camera.json" |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
start P --queue 8 --threads 4
OBSCURAD_URL="http://127.0.0.1:$PORT_P" CAM="fov_y=50&near=0.05&far=100&world_to_camera=$W2C" \
    EXR="$DATA/room_small.exr" CHROMIUM="$CHROMIUM" PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 \
    timeout 120 node "$B/preview.test.mjs" >"$T/browser.out" 2>&1
rc=$?
grep -v '^browser: ' "$T/browser.out"
check "the page's checks in Chromium (exit $rc)" "[ $rc -eq 0 ]"
check "daemon alive after the browser" "kill -0 $PID_P"
kill -TERM "$PID_P"
k=0
while [ $k -lt 100 ] && kill -0 "$PID_P" 2>/dev/null; do sleep 0.1; k=$((k + 1)); done
wait "$PID_P"; drc=$?
check "SIGTERM with the page's event stream open: exit $drc (0)" "[ $drc -eq 0 ]"
[ $failed -ne 0 ] && tail -5 "$T/P.log" | sed 's/^/       /'
echo "e2e browser: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
