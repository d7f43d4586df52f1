# Shared by the e2e scripts (sourced, not run: the Makefile runs only
# tests/e2e/*.sh).  Gives: a temp dir $T, removed on exit; every pid in
# $PIDS (and $PID, $CPIDS when a script sets them) killed on exit; the
# ok/bad/check counters, skip and gl_only; $CURL; and the daemon helpers
# start, post, get, error_is.  Each script ends with its own "passed,
# failed" line and exits 1 when a check failed.
T=$(mktemp -d)
PIDS=""
cleanup() {
    for p in $PIDS ${CPIDS:-} ${PID:-}; do kill -KILL "$p" 2>/dev/null; done
    rm -rf "$T"
}
trap cleanup EXIT
trap 'exit 1' INT TERM
pass=0
failed=0
ok() { pass=$((pass + 1)); echo "  ok   $*"; }
bad() { failed=$((failed + 1)); echo "  FAIL $*"; }
check() { if eval "$2"; then ok "$1"; else bad "$1"; fi; }
skipped=0
skip() { skipped=$((skipped + 1)); echo "  skip $*"; }
# CPU_DEVICE: 1 when the run is on the CPU device (OBSCURA_BACKEND=cpu,
# `make e2e OBSCURA_BACKEND=cpu`), which has no GL context.
CPU_DEVICE=0
[ "${OBSCURA_BACKEND:-}" = cpu ] && CPU_DEVICE=1
# Nothing named: the GL path (llvmpipe here), which the GL checks need; a
# run naming no backend would take the CPU device where no GPU is found.
[ -n "${OBSCURA_BACKEND:-}" ] || { OBSCURA_BACKEND=egl-surfaceless; export OBSCURA_BACKEND; }
# gl_only WHAT WHY: true on a GL backend; on the CPU device false, with a
# skip line naming WHAT and WHY it does not apply there, e.g.
#   if gl_only "the program cache" "the CPU device compiles no programs"; then ...
gl_only() {
    [ "$CPU_DEVICE" = 1 ] || return 0
    skip "$1: GL only ($2)"
    return 1
}
CURL="curl -s --max-time 60"

# start NAME ARGS...: starts obscurad on a free port (port 0; the port is
# read from its log), sets PID_NAME and PORT_NAME.
start() {
    name=$1; shift
    : > "$T/$name.log"
    "$OBSCURAD" --http 127.0.0.1:0 "$@" 2>"$T/$name.log" &
    pid=$!
    PIDS="$PIDS $pid"
    port=""
    i=0
    while [ $i -lt 300 ] && [ -z "$port" ]; do
        port=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/$name.log")
        kill -0 "$pid" 2>/dev/null || break
        [ -z "$port" ] && sleep 0.1
        i=$((i + 1))
    done
    eval "PID_$name=$pid; PORT_$name=$port"
    if [ -n "$port" ]; then ok "$name: obscurad started on 127.0.0.1:$port"; else
        bad "$name: obscurad did not start"; sed 's/^/       /' "$T/$name.log" | tail -5; exit 1; fi
}

# start_all NAME ARGS...: start with the binary protocol too, on a Unix
# socket ($T/NAME.sock) and TCP (a free port); sets SOCK_NAME and
# TCP_NAME besides PID_NAME and PORT_NAME.
start_all() {
    sname=$1; shift
    start "$sname" --socket "$T/$sname.sock" --tcp 127.0.0.1:0 "$@"
    tport=""
    i=0
    while [ $i -lt 300 ] && { [ -z "$tport" ] || [ ! -S "$T/$sname.sock" ]; }; do
        tport=$(sed -n 's/.*binary protocol on tcp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$T/$sname.log")
        [ -z "$tport" ] && sleep 0.1
        i=$((i + 1))
    done
    eval "SOCK_$sname=$T/$sname.sock; TCP_$sname=$tport"
    if [ -n "$tport" ] && [ -S "$T/$sname.sock" ]; then ok "$sname: binary protocol on tcp :$tport and unix:$T/$sname.sock"; else
        bad "$sname: the binary listeners did not start"; exit 1; fi
}

# post PORT QUERY FILE OUT [curl args]: prints the HTTP status
post() {
    p=$1 q=$2 f=$3 o=$4; shift 4
    $CURL -o "$o" -D "$o.h" -w '%{http_code}' -H 'Content-Type: image/x-exr' \
        --data-binary @"$f" "$@" "http://127.0.0.1:$p/v1/ao?$q"
}
# get PORT PATH OUT [curl args]: prints the HTTP status
get() {
    p=$1 path=$2 o=$3; shift 3
    $CURL -o "$o" -D "$o.h" -w '%{http_code}' "$@" "http://127.0.0.1:$p$path"
}
# error_is FILE CODE: the body is our JSON error with that code
error_is() { grep -q "\"code\":\"$2\"" "$1"; }

# expect CODE WHAT -- CMD...: runs CMD (stdout and stderr into $T/out and
# $T/err), passes when it exits CODE; said TEXT: the last CMD printed it
# (on a miss, the last lines of $T/err and $T/out; of $T/err alone when
# the script sets SAID_ERR_ONLY=1)
expect() {
    code=$1; what=$2; shift 3
    "$@" >"$T/out" 2>"$T/err"
    rc=$?
    if [ "$rc" -eq "$code" ]; then ok "$what"; else
        bad "$what (exit $rc, expected $code)"; sed 's/^/       /' "$T/err" | tail -5; fi
}
said() {
    if grep -q -- "$1" "$T/err" "$T/out"; then ok "message: $1"; else
        shown="$T/err"; [ -n "${SAID_ERR_ONLY:-}" ] || shown="$T/err $T/out"
        bad "message '$1' missing"; sed 's/^/       /' $shown | tail -5; fi
}
# field FILE EXPR: the value at EXPR (e.g. "['counts']['rays']") of a JSON file
field() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval('d'+sys.argv[2]))" "$@"; }
