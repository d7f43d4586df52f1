#!/bin/sh
# Runs the e2e scripts given on the command line, E2E_JOBS at a time
# (default: the machine's cores, at most 4), each with its output in its
# own log that is printed whole when the script ends, then "e2e: SCRIPT
# took N s".  The scripts named in E2E_ALONE (basenames without .sh) run
# afterwards, one at a time: their checks time the daemon (a drain that
# must end, a queue that must fill) and must not share the cores.  Every
# script picks its own ports (port 0) and temp dir, so they can run side
# by side.  Fails when any script fails; the failed ones are listed last.
#
#   E2E_JOBS=2 E2E_ALONE="drain load" tests/run_e2e.sh tests/e2e/*.sh
set -u

# one SCRIPT: runs it into its log, then prints the log and its time under
# a lock, so that two scripts' lines never interleave
one() {
    name=$(basename "$1" .sh)
    s=$(date +%s)
    if "$1" > "$dir/$name.log" 2>&1; then rc=0; else rc=1; fi
    t=$(($(date +%s) - s))
    (
        flock 9
        cat "$dir/$name.log"
        echo "e2e: $1 took $t s"
        [ $rc -eq 0 ] || echo "$1" >> "$dir/failed"
    ) 9> "$dir/lock"
}

# --one SCRIPT: this file called by xargs for one script (E2E_DIR set)
if [ "${1:-}" = --one ]; then
    dir=$E2E_DIR
    one "$2"
    exit 0
fi

jobs=${E2E_JOBS:-$(nproc 2>/dev/null || echo 1)}
[ "$jobs" -gt 4 ] && jobs=4
[ "$jobs" -lt 1 ] && jobs=1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
: > "$dir/failed"
alone=""
together=""
for t in "$@"; do
    case " ${E2E_ALONE:-} " in
    *" $(basename "$t" .sh) "*) alone="$alone $t" ;;
    *) together="$together $t" ;;
    esac
done

s0=$(date +%s)
if [ -n "$together" ]; then
    printf '%s\n' $together | E2E_DIR="$dir" xargs -P "$jobs" -n 1 "$0" --one
fi
for t in $alone; do
    one "$t"
done
n=$(wc -l < "$dir/failed")
echo "e2e: $# scripts in $(($(date +%s) - s0)) s ($jobs at a time, then$( [ -n "$alone" ] && echo "$alone" | sed 's|tests/e2e/||g; s|\.sh||g' || echo " none") alone); $n failed"
[ "$n" -eq 0 ] || { sed 's/^/e2e: FAILED /' "$dir/failed"; exit 1; }
exit 0
