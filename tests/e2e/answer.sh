#!/bin/sh
# End-to-end: the daemon's EXR answer, as the frame path writes it: each
# compression (query parameter and the CLI's --compression) written as
# named and decoding to the same AO; a bad one a 400 / usage error naming
# it; the half answer by default, float when asked; the stages of an HTTP
# frame in Server-Timing and /metrics.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/answer.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
CAMF="$DATA/room_small.camera.json"
. tests/e2e/lib/common.sh

# the compression byte of an EXR's header: the value after the second
# "compression" (the attribute's type name) and its 4-byte size
# (of part $2 of a multi-part file, default 0)
comp_of() {
    off=$(grep -abo compression "$1" | sed -n $((2 * ${2:-0} + 2))p | cut -d: -f1)
    [ -n "$off" ] && od -An -tu1 -j $((off + 16)) -N1 "$1" | tr -d ' '
}
mae() { "$OBSCURA" compare "$1" "$2" --mask none --json 2>/dev/null | sed -n 's/.*"mae": \([-0-9.e+]*\).*/\1/p'; }
# under `limit`: the daemon's GL run against obscura's own agrees to
# about 1e-7 (tests/e2e/daemon.sh), its half answers then to the same
# half values but for a rare rounding step
under() { [ -n "$1" ] && awk "BEGIN { exit !($1 < $2) }"; }

echo "e2e: the daemon's answer ($OBSCURAD)"
start A
A=$PORT_A
"$OBSCURA" ao "$R" --camera "$CAMF" --float -o "$T/local_f.exr" -q 2>/dev/null || bad "obscura ao --float failed"
"$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/local_h.exr" -q 2>/dev/null || bad "obscura ao failed"

echo "-- compression"
code=$(post $A "" "$R" "$T/auto.exr")
check "default answer: 200, RLE (auto)" "[ $code = 200 ] && [ \"\$(comp_of $T/auto.exr)\" = 1 ]"
n=0
for c in none rle zips zip piz; do
    code=$(post $A "compression=$c" "$R" "$T/$c.exr")
    m=$(mae "$T/local_h.exr" "$T/$c.exr")
    check "compression=$c: 200, written as $c ($n), AO = in-process half (MAE ${m:-?})" \
        "[ $code = 200 ] && [ \"\$(comp_of $T/$c.exr)\" = $n ] && under '$m' 1e-5"
    n=$((n + 1))
done
code=$(post $A "compression=b44" "$R" "$T/bad")
check "compression=b44: 400 bad_parameter naming the choices" \
    "[ $code = 400 ] && error_is $T/bad bad_parameter && grep -q 'none|rle|zips|zip|piz' $T/bad"
code=$(post $A "compression=dwaa" "$R" "$T/dwaa.exr")
check "compression=dwaa: 200 (OpenEXR 3.2+) or a 400 naming dwaa and the version ($code)" \
    "[ $code = 200 ] || { [ $code = 400 ] && grep -q 'dwaa needs OpenEXR 3.2' $T/dwaa.exr; }"
expect 0 "obscura ao --compression piz" -- "$OBSCURA" ao "$R" --camera "$CAMF" --compression piz -o "$T/cli_piz.exr" -q
check "  the file is PIZ (4) and its AO the ZIP file's" \
    "[ \"\$(comp_of $T/cli_piz.exr)\" = 4 ] && [ \"\$(mae $T/local_h.exr $T/cli_piz.exr)\" = 0 ]"
check "obscura ao writes ZIP (3) by default" "[ \"\$(comp_of $T/local_h.exr)\" = 3 ]"
expect 2 "obscura ao --compression lzw: a usage error" -- "$OBSCURA" ao "$R" --camera "$CAMF" --compression lzw -o "$T/x.exr"
said "parameter compression: 'lzw' is not one of"

echo "-- half by default, float when asked"
m=$(mae "$T/local_f.exr" "$T/auto.exr")
check "the default answer is half: it differs from the float AO, by under half's rounding (MAE ${m:-?})" \
    "[ -n '$m' ] && awk 'BEGIN { exit !($m > 0 && $m < 2.5e-4) }'"
code=$(post $A "float=1" "$R" "$T/float.exr")
m=$(mae "$T/local_f.exr" "$T/float.exr")
check "float=1: the float AO (MAE ${m:-?} < 1e-6)" "[ $code = 200 ] && under '$m' 1e-6"
code=$(post $A "float=1&compression=none" "$R" "$T/fn.exr")
check "  uncompressed, about twice the half answer's bytes" \
    "[ $code = 200 ] && [ \$(wc -c < $T/fn.exr) -gt \$((19 * \$(wc -c < $T/none.exr) / 10)) ]"

echo "-- obscura ao --server: the answer the file needs"
"$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/sv_h.exr" --server "http://127.0.0.1:$A" -q 2>/dev/null
"$OBSCURA" ao "$R" --camera "$CAMF" --float -o "$T/sv_f.exr" --server "http://127.0.0.1:$A" -q 2>/dev/null
outs=$(grep 'POST /v1/ao status=200' "$T/A.log" | tail -2 | sed -n 's/.* out=\([0-9]*\) .*/\1/p' | tr '\n' ' ')
check "the half file asks for a half answer, --float for a float one (answer bytes: $outs)" \
    "echo '$outs' | awk '{ exit !(NF == 2 && 2 * \$1 < \$2) }'"
check "  each file the same bytes as obscura ao's own" \
    "cmp -s $T/local_h.exr $T/sv_h.exr && cmp -s $T/local_f.exr $T/sv_f.exr"

echo "-- the deep answer's compression"
D=$DATA/deep_small.exr
code=$(post $A "output=deep" "$D" "$T/deep_auto.exr")
check "output=deep: 200, the file's compressions (ZIPS deep part, ZIP flat part) as obscura ao writes them" \
    "[ $code = 200 ] && [ \"\$(comp_of $T/deep_auto.exr 0)\" = 2 ] && [ \"\$(comp_of $T/deep_auto.exr 1)\" = 3 ]"
code=$(post $A "output=deep&compression=rle" "$D" "$T/deep_rle.exr")
check "output=deep&compression=rle: both parts RLE" \
    "[ $code = 200 ] && [ \"\$(comp_of $T/deep_rle.exr 0)\" = 1 ] && [ \"\$(comp_of $T/deep_rle.exr 1)\" = 1 ]"
code=$(post $A "output=deep&compression=piz" "$D" "$T/deep_piz")
check "output=deep&compression=piz: refused ($code), naming what deep data takes" \
    "[ $code != 200 ] && grep -q 'deep part takes none, rle, zips' $T/deep_piz"
"$OBSCURA" ao "$D" --output deep --compression rle -o "$T/deep_cli.exr" -q 2>/dev/null
"$OBSCURA" ao "$D" --output deep --compression rle -o "$T/deep_sv.exr" --server "http://127.0.0.1:$A" -q 2>/dev/null
check "obscura ao --output deep --compression rle: RLE, and --server's file the same bytes" \
    "[ \"\$(comp_of $T/deep_cli.exr 0)\" = 1 ] && cmp -s $T/deep_cli.exr $T/deep_sv.exr"

echo "-- stages"
check "Server-Timing: queue, decode, gl, encode, receive" \
    "grep -qi '^Server-Timing: queue;dur=.*decode;dur=.*gl;dur=.*encode;dur=.*receive;dur=' $T/auto.exr.h"
get $A /metrics "$T/m" >/dev/null
check "/metrics: receive and send stages counted" \
    "grep -q 'obscurad_stage_seconds_count{stage=\"receive\"} [1-9]' $T/m && grep -q 'obscurad_stage_seconds_count{stage=\"send\"} [1-9]' $T/m"
check "the request log has receive=" "grep -q 'POST /v1/ao status=200 .* encode=[0-9.]* receive=[0-9.]* total=' $T/A.log"
echo "e2e answer: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
