#!/bin/sh
# End-to-end tests of the command-line conventions users bring from
# oiiotool, oidnDenoise, Nuke and the farms (issue 29, items 7, 11, 13):
# `-` as stdin and stdout for `obscura ao` (stdout needs --format);
# `obscura COMMAND --help`; "did you mean" on an unknown option; help
# lines never cut; an `error:` prefix on every error; a file's control
# bytes escaped in messages; the frame number last in derived output
# names; `Progress: N%` lines of the bakes under --progress percent.
#
#   OBSCURA=build/obscura tests/e2e/cli_conventions.sh
set -u
OBSCURA=${OBSCURA:-build/obscura}
case $OBSCURA in /*) ;; *) OBSCURA="$(pwd)/$OBSCURA" ;; esac
DATA="$(pwd)/tests/data"
R="$DATA/room_small.exr"
CAMF="$DATA/room_small.camera.json"
. tests/e2e/lib/common.sh

echo "e2e cli conventions: $OBSCURA"

echo "-- '-' as stdin and stdout (item 7)"
"$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/ref.exr" -q 2>/dev/null
"$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/ref.png" -q 2>/dev/null
"$OBSCURA" ao - --camera "$CAMF" -o "$T/in.exr" -q <"$R" 2>"$T/err"
rc=$?
check "ao - (stdin): exit $rc, the bytes of ao FILE" "[ $rc -eq 0 ] && cmp -s '$T/ref.exr' '$T/in.exr'"
(cd "$T" && "$OBSCURA" ao "$R" --camera "$CAMF" -o - --format exr -q >"$T/out.exr" 2>"$T/err")
rc=$?
check "-o - --format exr: exit $rc, the bytes on stdout, no file named '-'" \
    "[ $rc -eq 0 ] && cmp -s '$T/ref.exr' '$T/out.exr' && [ ! -e '$T/-' ]"
"$OBSCURA" ao - --camera "$CAMF" -o - --format png -q <"$R" >"$T/pipe.png" 2>"$T/err"
rc=$?
check "ao - -o - --format png (a pipe): exit $rc, the PNG's bytes" "[ $rc -eq 0 ] && cmp -s '$T/ref.png' '$T/pipe.png'"
"$OBSCURA" ao "$R" --camera "$CAMF" -o - -q >"$T/o" 2>"$T/err"
rc=$?
check "-o - without --format: exit $rc (2), says to add --format" \
    "[ $rc -eq 2 ] && grep -q 'error: ao: -o - writes to stdout.*--format exr or --format png' '$T/err' && [ ! -s '$T/o' ]"
"$OBSCURA" ao "$R" --camera "$CAMF" -o - --format png --output both -q >"$T/o" 2>"$T/err"
rc=$?
check "-o - --format png with two outputs: exit $rc (2)" "[ $rc -eq 2 ] && grep -q 'several PNGs' '$T/err'"
"$OBSCURA" ao - --camera "$CAMF" -o "$T/x.exr" --server unix:/nonexistent -q <"$R" 2>"$T/err"
rc=$?
check "ao - with --server: exit $rc (2), says why" "[ $rc -eq 2 ] && grep -q 'stdin' '$T/err'"
"$OBSCURA" ao - -o - --format exr -q <"$DATA/deep_small.exr" >"$T/deep.exr" 2>"$T/err"
rc=$?
"$OBSCURA" ao "$DATA/deep_small.exr" -o "$T/deepref.exr" -q 2>/dev/null
check "deep EXR through stdin and stdout: exit $rc, the bytes of ao FILE" \
    "[ $rc -eq 0 ] && cmp -s '$T/deepref.exr' '$T/deep.exr'"

echo "-- help and options (item 11)"
for cmd in ao batch compare inspect bake bake-dynamic gbuffer warmup; do
    "$OBSCURA" "$cmd" --help >"$T/out" 2>"$T/err"
    rc=$?
    check "obscura $cmd --help: exit $rc (0), its usage on stdout" "[ $rc -eq 0 ] && grep -q 'obscura $cmd' '$T/out'"
done
"$OBSCURA" help >"$T/out"
check "help: the --output line whole (...|aovs|deep)" "grep -q -- '--output ao|composite|both|samples|cull|bleed|luminance|multibounce|bent|aovs|deep\$' '$T/out'"
"$OBSCURA" ao "$R" -o "$T/x.exr" --radiu 0.4 2>"$T/err"
rc=$?
check "--radiu: exit $rc (2), did you mean --radius?" "[ $rc -eq 2 ] && grep -q \"error: unknown option '--radiu'; did you mean --radius?\" '$T/err'"
"$OBSCURA" ao "$R" -o "$T/x.exr" --smaples 8 2>"$T/err"
check "--smaples: did you mean --samples?" "grep -q 'did you mean --samples?' '$T/err'"
"$OBSCURA" ao "$R" -o "$T/x.exr" --no-such-flag 1 2>"$T/err"
check "--no-such-flag: no suggestion far from every name" "grep -q \"unknown option '--no-such-flag'\$\" '$T/err'"

echo "-- messages (item 11)"
"$OBSCURA" ao "$R" -o "$T/x.exr" --solve-camera=0 -q 2>"$T/err"
rc=$?
check "no camera: exit $rc (3), the NO_CAMERA line starts 'obscura: error:'" \
    "[ $rc -eq 3 ] && grep -q '^obscura: error: .*(NO_CAMERA)\$' '$T/err'"
# the depth channel renamed in the header to bytes that clear a terminal
python3 -c "
import sys
d = open(sys.argv[1], 'rb').read()
open(sys.argv[2], 'wb').write(d.replace(b'ViewLayer.Depth.Z\x00', b'ViewLayer.Dep\x1b[2J\x00', 1))
" "$R" "$T/ctl.exr"
"$OBSCURA" ao "$T/ctl.exr" --camera "$CAMF" -o "$T/x.exr" -q 2>"$T/err"
rc=$?
check "a channel name with ESC: exit $rc (3), shown as \\x1b, no raw control byte" \
    "[ $rc -eq 3 ] && grep -q 'ViewLayer.Dep\\\\x1b\\[2J' '$T/err' && ! tr -d '\\n' <'$T/err' | grep -q '[[:cntrl:]]'"

echo "-- output names (item 11)"
mkdir -p "$T/n"
"$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/n/comp.0001.png" --output both -q 2>"$T/err"
check "--output both to comp.0001.png: comp.ao.0001.png and comp.composite.0001.png (the frame last)" \
    "[ -s '$T/n/comp.ao.0001.png' ] && [ -s '$T/n/comp.composite.0001.png' ] && [ ! -e '$T/n/comp.0001.ao.png' ]"
"$OBSCURA" ao "$R" --camera "$CAMF" -o "$T/n/plain.png" --output both -q 2>"$T/err"
check "... and plain.png: plain.ao.png, plain.composite.png (no frame number: as before)" \
    "[ -s '$T/n/plain.ao.png' ] && [ -s '$T/n/plain.composite.png' ]"

echo "-- the bakes' progress (item 13)"
FIX=$DATA/levels/aalborg_cut.acc
"$OBSCURA" bake "$FIX" -o "$T/a.glb" --rays 16 --progress percent >"$T/out" 2>"$T/err"
rc=$?
check "bake --progress percent: exit $rc, 'Progress: N%' lines on stdout, rising to 100%" \
    "[ $rc -eq 0 ] && [ \"\$(tail -1 '$T/out')\" = 'Progress: 100%' ] && ! grep -qv '^Progress: [0-9]*%\$' '$T/out' && sort -c -n -k2 '$T/out'"
"$OBSCURA" bake-dynamic "$FIX" -o "$T/m.json" --rays 64 --max-regions 24 -q --progress percent >"$T/out" 2>"$T/err"
rc=$?
check "bake-dynamic --progress percent: exit $rc, ends 'Progress: 100%'" \
    "[ $rc -eq 0 ] && [ \"\$(tail -1 '$T/out')\" = 'Progress: 100%' ]"
"$OBSCURA" bake "$FIX" -o "$T/a.glb" --progress bar 2>"$T/err"
rc=$?
check "bake --progress bar: exit $rc (2)" "[ $rc -eq 2 ]"

[ $failed -ne 0 ] && sed 's/^/       /' "$T/err"
echo "e2e cli conventions: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
