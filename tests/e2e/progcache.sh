#!/bin/sh
# The program cache (core/gl/progcache.c, README "Program cache"), with
# Mesa's own cache off (MESA_SHADER_CACHE_DISABLE=true) so that nothing
# comes from ~/.cache: a first process compiles N > 0 programs, a second
# compiles none and loads N, and both write the same bytes as a run
# without a cache; OBSCURA_CACHE_DIR and the XDG default; damaged entries
# (ours and Mesa's) are rebuilt with the same output; a folder that
# cannot be made costs one log line; obscura warmup --methods all leaves
# nothing to compile for any method; obscurad counts the programs in
# /v1/info and /metrics.  Counters, not timings.  On the CPU device
# (OBSCURA_BACKEND=cpu): that it compiles nothing and makes no folder.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/progcache.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
. tests/e2e/lib/common.sh
export MESA_SHADER_CACHE_DISABLE=true
unset OBSCURA_CACHE_DIR MESA_SHADER_CACHE_DIR MESA_GLSL_CACHE_DIR
ROOM="$DATA/room_small.exr --camera $DATA/room_small.camera.json"

# run NAME ARGS...: obscura ao -v on room_small, stderr in $T/NAME.err;
# sets RC, and COMPILED, LOADED, REJECTED from its "programs:" line
run() {
    name=$1; shift
    # shellcheck disable=SC2086
    "$OBSCURA" ao $ROOM -o "$T/$name.exr" -v "$@" 2> "$T/$name.err"
    RC=$?
    line=$(grep 'programs: ' "$T/$name.err" | tail -1)
    COMPILED=$(echo "$line" | sed -n 's/.*programs: \([0-9]*\) compiled.*/\1/p')
    LOADED=$(echo "$line" | sed -n 's/.* \([0-9]*\) loaded.*/\1/p')
    REJECTED=$(echo "$line" | sed -n 's/.* \([0-9]*\) rejected.*/\1/p')
}

echo "e2e progcache: the program cache"
# The CPU device (OBSCURA_BACKEND=cpu) compiles nothing: what it has of
# the cache is that it uses none, makes no folder and counts nothing.
if [ "$CPU_DEVICE" = 1 ]; then
    C="$T/cache"
    run cpu --cache-dir "$C"
    check "the CPU device: exit 0, no programs line, no cache folder made" \
        "[ $RC -eq 0 ] && [ -z '$COMPILED' ] && ! grep -q 'programs: ' '$T/cpu.err' && [ ! -e '$C' ]"
    "$OBSCURA" warmup --methods all --cache-dir "$C" > "$T/warmup.out" 2>&1
    rc=$?
    check "warmup --methods all on the CPU device: exit $rc (0), nothing to warm up, no folder made" \
        "[ $rc -eq 0 ] && grep -q 'nothing to warm up' '$T/warmup.out' && [ ! -e '$C' ]"
    "$OBSCURA" warmup --methods bogus --cache-dir "$C" > "$T/bogus" 2>&1
    rc=$?
    check "warmup --methods bogus: exit 2 naming it ($rc)" "[ $rc -eq 2 ] && grep -q \"'bogus' is not one of\" '$T/bogus'"
    start d --cache-dir "$C"
    code=$(post "$PORT_d" "fov_y=50&output=ao&format=exr" "$DATA/room_small.exr" "$T/d.exr")
    get "$PORT_d" /v1/info "$T/info.json" > /dev/null
    get "$PORT_d" /metrics "$T/metrics" > /dev/null
    check "obscurad on the CPU device: a frame ($code), /v1/info's program_cache: no folder, nothing counted" \
        "[ '$code' = 200 ] && python3 -c 'import json,sys; p=json.load(open(sys.argv[1]))[\"program_cache\"]; sys.exit(not (p[\"dir\"] is None and p[\"compiled\"]==0 and p[\"loaded\"]==0))' '$T/info.json' && grep -q '^obscurad_programs_compiled_total 0\$' '$T/metrics' && [ ! -e '$C' ]"
    kill "$PID_d"; wait "$PID_d" 2>/dev/null
    gl_only "the program cache's entries, damaged entries, folders, warmup's programs and a recreated context's loads" \
        "the CPU device compiles no programs"
    echo "e2e progcache: $pass passed, $failed failed, $skipped skipped"
    [ "$failed" -eq 0 ]
    exit
fi
C="$T/cache"
run nocache --cache-dir ''
check "no cache: exit 0, programs compiled ($COMPILED), none loaded" \
    "[ $RC -eq 0 ] && [ '${COMPILED:-0}' -gt 0 ] && [ '$LOADED' = 0 ]"
run first --cache-dir "$C"
N=$COMPILED
check "fresh cache: the first process compiles N=$N > 0, loads none" "[ '${N:-0}' -gt 0 ] && [ '$LOADED' = 0 ]"
check "the first process stored N entries" "[ \$(ls '$C/programs' | grep -c '\.bin\$') -eq ${N:-0} ]"
run second --cache-dir "$C"
check "a second process compiles 0 and loads N ($COMPILED, $LOADED)" "[ '$COMPILED' = 0 ] && [ '$LOADED' = '$N' ]"
check "output byte-identical to the first and to a run without a cache" \
    "cmp -s '$T/first.exr' '$T/second.exr' && cmp -s '$T/first.exr' '$T/nocache.exr'"
check "Mesa's shader cache lives in the folder too, although MESA_SHADER_CACHE_DISABLE=true" \
    "[ -d '$C/mesa_shader_cache' ] && grep -q 'MESA_SHADER_CACHE_DISABLE is set' '$T/second.err'"
OBSCURA_CACHE_DIR="$C" run env
check "OBSCURA_CACHE_DIR: the same folder ($COMPILED compiled, $LOADED loaded)" "[ '$COMPILED' = 0 ] && [ '$LOADED' = '$N' ]"
mkdir -p "$T/home"
HOME="$T/home" XDG_CACHE_HOME= run home
check "default: \$HOME/.cache/obscura when XDG_CACHE_HOME is unset" \
    "[ '$COMPILED' = '$N' ] && ls '$T/home/.cache/obscura/programs' | grep -q '\.bin\$'"
mkdir -p "$T/xdg"
XDG_CACHE_HOME="$T/xdg" run xdg
check "default: \$XDG_CACHE_HOME/obscura" "[ '$COMPILED' = '$N' ] && [ -d '$T/xdg/obscura/programs' ]"
"$OBSCURA" info --cache-dir "$C" > "$T/info" 2>&1
check "obscura info names the cache" "grep -q 'program cache: $C' '$T/info'"

echo "-- damaged entries"
for f in "$C"/programs/*.bin; do
    size=$(stat -c %s "$f")
    head -c $((size / 2)) "$f" > "$f.cut" && mv "$f.cut" "$f"
done
# Mesa's own entries too: every byte after the first 64 inverted
find "$C/mesa_shader_cache" -type f ! -name index | while read -r f; do
    python3 -c 'import sys; b=bytearray(open(sys.argv[1],"rb").read()); b[64:]=bytes(x^0xff for x in b[64:]); open(sys.argv[1],"wb").write(b)' "$f"
done
run damaged --cache-dir "$C"
check "truncated entries: exit 0, N rejected and rebuilt ($REJECTED, $COMPILED)" \
    "[ $RC -eq 0 ] && [ '$REJECTED' = '$N' ] && [ '$COMPILED' = '$N' ] && [ '$LOADED' = 0 ]"
check "output byte-identical after damaged entries (ours and Mesa's)" "cmp -s '$T/first.exr' '$T/damaged.exr'"
run rebuilt --cache-dir "$C"
check "the rebuilt entries load ($COMPILED compiled, $LOADED loaded)" "[ '$COMPILED' = 0 ] && [ '$LOADED' = '$N' ]"
for f in "$C"/programs/*.bin; do cp "$(ls "$C"/programs/*.bin | head -1)" "$f.x"; mv "$f.x" "$f"; done
run swapped --cache-dir "$C"
check "every entry replaced by another program's: N-1 rejected ($REJECTED), same output" \
    "[ '$REJECTED' = $((N - 1)) ] && [ '$COMPILED' = $((N - 1)) ] && cmp -s '$T/first.exr' '$T/swapped.exr'"

echo "-- folders that cannot be used"
run proc --cache-dir /proc/obscura-no-such/cache
lines=$(grep -c 'program cache' "$T/proc.err")
check "a folder that cannot be made: exit 0, exactly one log line ($lines), no cache, same output" \
    "[ $RC -eq 0 ] && [ $lines -eq 1 ] && grep -q 'program cache off' '$T/proc.err' && cmp -s '$T/first.exr' '$T/proc.exr'"
: > "$T/plainfile"
run file --cache-dir "$T/plainfile/cache"
lines=$(grep -c 'program cache' "$T/file.err")
check "a folder under a plain file: one log line ($lines), same output" \
    "[ $lines -eq 1 ] && cmp -s '$T/first.exr' '$T/file.exr'"
HOME= XDG_CACHE_HOME= run nohome
lines=$(grep -c 'program cache' "$T/nohome.err")
check "no HOME, no XDG_CACHE_HOME: one line saying the cache is off ($lines)" \
    "[ $lines -eq 1 ] && grep -q 'program cache off: no folder' '$T/nohome.err' && cmp -s '$T/first.exr' '$T/nohome.exr'"
if [ "$(id -u)" -ne 0 ]; then
    mkdir -p "$T/ro" && cp -r "$C/programs" "$T/ro/" && chmod 555 "$T/ro/programs"
    run ro --cache-dir "$T/ro"
    check "a read-only folder: programs load ($LOADED), one line says read-only" \
        "[ '$LOADED' = '$N' ] && [ \$(grep -c 'program cache' '$T/ro.err') -eq 1 ] && grep -q 'read-only' '$T/ro.err'"
    chmod 755 "$T/ro/programs"
else
    echo "  skip a read-only folder: root writes to any folder"
fi

echo "-- obscura warmup"
W="$T/warm"
"$OBSCURA" warmup --methods all --cache-dir "$W" > "$T/warmup.out" 2> "$T/warmup.err"
check "warmup --methods all: exit 0, programs built" \
    "[ \$? -eq 0 ] && grep -q 'programs built and stored' '$T/warmup.out' && ! grep -q ' 0 programs built' '$T/warmup.out'"
mesa_entries() { find "$W/mesa_shader_cache" -type f 2>/dev/null | wc -l; }
before=$(mesa_entries)
for m in vaopp vao hemisphere angle hbao gtao; do
    run "warm_$m" --cache-dir "$W" --method "$m" --output both
    check "after warmup, method $m compiles nothing ($COMPILED compiled, $LOADED loaded)" \
        "[ '$COMPILED' = 0 ] && [ '${LOADED:-0}' -gt 0 ]"
done
run "warm_preview" --cache-dir "$W" --quality preview --output both
check "after warmup, --quality preview (its downsample and upsample) compiles nothing ($COMPILED compiled, $LOADED loaded)" \
    "[ '$COMPILED' = 0 ] && [ '${LOADED:-0}' -gt 0 ]"
"$OBSCURA" ao "$DATA/deep_small.exr" --fov-y 50 -o "$T/deep.exr" -v --cache-dir "$W" 2> "$T/deep.err"
check "after warmup, deep input compiles nothing" "grep -q 'programs: 0 compiled' '$T/deep.err'"
# llvmpipe's machine code too: Mesa's cache gains nothing from these frames
# (deep_small is 48x32, a power-of-two height: warmup's sizes cover it)
after=$(mesa_entries)
check "after warmup, Mesa's cache gains no entry from these frames ($before -> $after)" "[ $before -eq $after ]"
"$OBSCURA" warmup --methods all --cache-dir "$W" > "$T/warmup2.out" 2>&1
check "a second warmup builds nothing" "grep -q ' 0 programs built' '$T/warmup2.out'"
"$OBSCURA" warmup --methods bogus --cache-dir "$W" > "$T/bogus" 2>&1
rc=$?
check "warmup --methods bogus: exit 2 naming it ($rc)" "[ $rc -eq 2 ] && grep -q \"'bogus' is not one of\" '$T/bogus'"
"$OBSCURA" warmup --cache-dir '' > "$T/off" 2>&1
rc=$?
check "warmup with the cache off: exit 1 ($rc)" "[ $rc -eq 1 ] && grep -q 'off' '$T/off'"
"$OBSCURA" warmup --cache-dir /proc/obscura-no-such > "$T/nowrite" 2>&1
rc=$?
check "warmup into a folder that cannot be made: exit 1 ($rc)" "[ $rc -eq 1 ] && grep -q 'no writable program cache' '$T/nowrite'"

echo "-- obscurad"
start d --cache-dir "$W"
code=$(post "$PORT_d" "fov_y=50&output=ao&format=exr" "$DATA/room_small.exr" "$T/d.exr")
check "a frame: 200 ($code)" "[ '$code' = 200 ]"
get "$PORT_d" /v1/info "$T/info.json" > /dev/null
check "/v1/info: program_cache names the folder, 0 compiled, programs loaded" \
    "python3 -c 'import json,sys; p=json.load(open(sys.argv[1]))[\"program_cache\"]; sys.exit(not (p[\"dir\"]==sys.argv[2] and p[\"writable\"] and p[\"compiled\"]==0 and p[\"loaded\"]>0))' '$T/info.json' '$W'"
get "$PORT_d" /metrics "$T/metrics" > /dev/null
check "/metrics: obscurad_programs_compiled_total 0, loaded > 0" \
    "grep -q '^obscurad_programs_compiled_total 0\$' '$T/metrics' && grep -q '^obscurad_programs_loaded_total [1-9]' '$T/metrics'"
kill "$PID_d"; wait "$PID_d" 2>/dev/null
# a GL failure recreates the context: the new one loads too, and the
# counters go on over both contexts
start f --cache-dir "$W" --fail-gl-after 2
post "$PORT_f" "fov_y=50&output=ao&format=exr" "$DATA/room_small.exr" "$T/f1.exr" > /dev/null
get "$PORT_f" /v1/info "$T/f1.json" > /dev/null
c2=$(post "$PORT_f" "fov_y=50&output=ao&format=exr" "$DATA/room_small.exr" "$T/f2.exr")
i=0
while [ $i -lt 100 ] && ! grep -q 'GL context recreated' "$T/f.log"; do sleep 0.1; i=$((i + 1)); done
c3=$(post "$PORT_f" "fov_y=50&output=ao&format=exr" "$DATA/room_small.exr" "$T/f3.exr")
get "$PORT_f" /v1/info "$T/f3.json" > /dev/null
check "after a recreated context (frame 2: $c2, frame 3: $c3): 0 compiled, loaded twice as many" \
    "[ '$c2' = 500 ] && [ '$c3' = 200 ] && python3 -c 'import json,sys; a=json.load(open(sys.argv[1]))[\"program_cache\"]; b=json.load(open(sys.argv[2]))[\"program_cache\"]; sys.exit(not (b[\"compiled\"]==0 and a[\"loaded\"]>0 and b[\"loaded\"]==2*a[\"loaded\"]))' '$T/f1.json' '$T/f3.json' && cmp -s '$T/f1.exr' '$T/f3.exr'"
kill "$PID_f"; wait "$PID_f" 2>/dev/null
start e --cache-dir ''
code=$(post "$PORT_e" "fov_y=50&output=ao&format=exr" "$DATA/room_small.exr" "$T/e.exr")
get "$PORT_e" /v1/info "$T/info2.json" > /dev/null
check "obscurad --cache-dir '': no cache, programs compiled, same bytes" \
    "[ '$code' = 200 ] && python3 -c 'import json,sys; p=json.load(open(sys.argv[1]))[\"program_cache\"]; sys.exit(not (p[\"dir\"] is None and p[\"compiled\"]>0))' '$T/info2.json' && cmp -s '$T/d.exr' '$T/e.exr'"
kill "$PID_e"; wait "$PID_e" 2>/dev/null

echo "e2e progcache: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
