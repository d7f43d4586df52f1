#!/bin/sh
# End-to-end tests of clients/python/obscura_client.py against a real
# obscurad on HTTP, a Unix socket and TCP: the same answer, byte for byte,
# as `obscura ao` writes in process, over every transport and from a path,
# bytes or a file object; the answer streamed into a file; errors as
# ObscuraError with the daemon's JSON code; the daemon's warnings as
# ObscuraWarning and Answer.warnings over every transport; Camera.from_json
# and the header attributes of obscura ao --camera; run with `python3 -I`
# (no site packages, no PYTHONPATH), as in the Pythons of DCC applications.
#
#   OBSCURA=build/obscura OBSCURAD=build/obscurad tests/e2e/python_client.sh
#
# The daemon it starts is killed on exit; every wait is bounded.
set -u
OBSCURA=${OBSCURA:-build/obscura}
OBSCURAD=${OBSCURAD:-build/obscurad}
DATA=tests/data
R="$DATA/room_small.exr"
. tests/e2e/lib/common.sh

echo "e2e python client: $OBSCURAD"
if ! command -v python3 >/dev/null 2>&1; then
    echo "  FAIL python3 not found (tools/deps.sh)"
    exit 1
fi
W2C=$(tr -d ' \n' < "$DATA/room_small.camera.json" |
    sed 's/.*"world_to_camera":\[\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\],\[\([^]]*\)\]\].*/\1,\2,\3,\4/')
CAM_CLI="--fov-y 50 --near 0.05 --far 100 --world-to-camera $W2C"
start_all d --max-body 8m --queue 4
HP=$PORT_d TP=$TCP_d SOCK=$SOCK_d

# py ARGS...: the client's folder on sys.path by hand, nothing else
cat > "$T/run.py" <<'EOF'
import io, os, sys
sys.path.insert(0, os.path.join(os.getcwd(), "clients", "python"))
import obscura_client as oc

# the fifth argument: the camera's world_to_camera (ao), the decorators file (bake_*)
mode, server, src, out, extra = sys.argv[1:6]
cam = {} if mode.startswith("bake_") else dict(fov_y=50, near=0.05, far=100,
                                               world_to_camera=[float(x) for x in extra.split(",")])
seen = []  # oc.bake's progress
try:
    if mode == "bake_path":
        data = oc.bake(src, server=server, rays=16, distances=(2, 300), poll=0.1,
                       progress=lambda d, st: seen.append((d, st)))
        print("progress %d looks, last %s %s" % (len(seen), seen[-1][0], seen[-1][1]))
        assert seen[-1] == (1, "done"), seen[-1]
    elif mode == "bake_decorators":
        data = oc.bake(open(src, "rb").read(), server=server, decorators=extra, rays=16,
                       distances=(2, 300), poll=0.1)
    elif mode == "bake_out":
        assert oc.bake(src, server=server, out=out, rays=16, distances=(2, 300), poll=0.1) is None
        data = open(out, "rb").read()
    elif mode == "bake_badrules":
        data = oc.bake(src, server=server, decorators=b"not json", rays=16)
    elif mode == "bake_failed":
        data = oc.bake(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n", server=server, rays=4, poll=0.1)
    elif mode == "bake_binary":
        data = oc.bake(src, server=server.replace("http://", "tcp://"), rays=4)
    elif mode == "path":
        data = oc.ao(src, server=server, **cam)
    elif mode == "bytes":
        data = oc.ao(open(src, "rb").read(), server=server, **cam)
    elif mode == "file":
        with open(src, "rb") as f:
            data = oc.ao(f, server=server, **cam)
    elif mode == "stream":
        data = oc.ao(src, server=server, out=out, **cam)
        assert data == b"" and data.warnings == [], (data, data.warnings)
        data = open(out, "rb").read()
    elif mode == "switches":  # True/False: a parameter's switch and a request option
        data = oc.ao(src, server=server, blur=False, float=True, **cam)
    elif mode == "png":
        data = oc.ao(src, server=server, format="png", png_bits=16, **cam)
    elif mode == "missing":
        data = oc.ao(src, server=server, depth="NoSuchChannel", **cam)
    elif mode == "badparam":
        data = oc.ao(src, server=server, radius=-3, **cam)
    elif mode == "nocamera":
        data = oc.ao(src, server=server, solve_camera=0)  # room_small's P would give one
    elif mode == "failout":
        data = oc.ao(src, server=server, out=out, depth="NoSuchChannel", **cam)
    else:
        raise SystemExit("unknown mode " + mode)
except oc.ObscuraError as e:
    print("error status=%s code=%s message=%s" % (e.status, e.code, e.message))
    raise SystemExit(3)
open(out, "wb").write(data)
print("ok %d bytes" % len(data))
EOF
py() { python3 -I -B "$T/run.py" "$@"; }

echo "-- the same bytes as the CLI, over every transport"
# shellcheck disable=SC2086
# --compression rle: the daemon's answer's auto (the CLI's file default is zip)
"$OBSCURA" ao "$R" $CAM_CLI --compression rle -o "$T/cli.exr" -q 2>/dev/null
for url in "http://127.0.0.1:$HP" "unix:$SOCK" "tcp://127.0.0.1:$TP"; do
    for mode in path bytes file stream; do
        py "$mode" "$url" "$R" "$T/py.exr" "$W2C" >"$T/out" 2>&1
        rc=$?
        check "${url%%:*} from a $mode: exit $rc, the CLI's bytes ($(cat "$T/out" | head -c 80))" \
            "[ $rc -eq 0 ] && cmp -s '$T/cli.exr' '$T/py.exr'"
        rm -f "$T/py.exr"
    done
done
# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI --png-bits 16 -o "$T/cli.png" -q 2>/dev/null
py png "tcp://127.0.0.1:$TP" "$R" "$T/py.png" "$W2C" >/dev/null 2>&1
check "tcp format=png png_bits=16: the CLI's PNG" "cmp -s '$T/cli.png' '$T/py.png'"

# shellcheck disable=SC2086
"$OBSCURA" ao "$R" $CAM_CLI --blur off --float --compression rle -o "$T/cli_sw.exr" -q 2>/dev/null
for url in "http://127.0.0.1:$HP" "tcp://127.0.0.1:$TP"; do
    py switches "$url" "$R" "$T/py_sw.exr" "$W2C" >"$T/out" 2>&1
    check "${url%%:*} blur=False float=True: the CLI's --blur off --float bytes ($(head -c 80 "$T/out"))" \
        "cmp -s '$T/cli_sw.exr' '$T/py_sw.exr'"
    rm -f "$T/py_sw.exr"
done

echo "-- errors carry the daemon's code"
for url in "http://127.0.0.1:$HP" "unix:$SOCK"; do
    py missing "$url" "$R" "$T/x.exr" "$W2C" >"$T/out" 2>&1
    rc=$?
    check "${url%%:*} missing channel: exit $rc, ObscuraError missing_channel 422 ($(head -c 90 "$T/out"))" \
        "[ $rc -eq 3 ] && grep -q 'status=422 code=missing_channel message=.*NoSuchChannel' '$T/out'"
    py badparam "$url" "$R" "$T/x.exr" "$W2C" >"$T/out" 2>&1
    check "${url%%:*} radius=-3: bad_parameter 400 naming radius" \
        "grep -q 'status=400 code=bad_parameter message=.*radius' '$T/out'"
done
py nocamera "tcp://127.0.0.1:$TP" "$R" "$T/x.exr" "$W2C" >"$T/out" 2>&1
check "tcp no camera: no_camera ($(head -c 80 "$T/out"))" "grep -q 'code=no_camera' '$T/out'"
py failout "http://127.0.0.1:$HP" "$R" "$T/fail.exr" "$W2C" >/dev/null 2>&1
check "a refused request leaves no output file behind" "[ ! -e '$T/fail.exr' ] && [ ! -e '$T/fail.exr.part' ]"
py path "http://127.0.0.1:1" "$R" "$T/x.exr" "$W2C" >"$T/out" 2>&1
check "an unreachable daemon: ObscuraError unreachable" "grep -q 'status=None code=unreachable' '$T/out'"
py path "ftp://x" "$R" "$T/x.exr" "$W2C" >"$T/out" 2>&1
check "a server it cannot talk to: ValueError naming it" "grep -q \"ValueError: ao(): server 'ftp://x'\" '$T/out'"

echo "-- bake jobs: oc.bake()"
FIX=tests/data/levels/aalborg_cut.acc
TREES=tests/data/levels/aalborg_cut.trees.json
"$OBSCURA" bake "$FIX" -o "$T/cli_bake.glb" --rays 16 --distances 2,300 -q
"$OBSCURA" bake "$FIX" -o "$T/cli_dec.glb" --rays 16 --distances 2,300 --decorators "$TREES" -q
py bake_path "http://127.0.0.1:$HP" "$FIX" "$T/py_bake.glb" - >"$T/out" 2>&1
check "bake from a path: obscura bake's bytes, progress to 1 and done ($(head -c 60 "$T/out"))" \
    "cmp -s '$T/cli_bake.glb' '$T/py_bake.glb' && grep -q 'last 1 done' '$T/out'"
py bake_decorators "http://127.0.0.1:$HP" "$FIX" "$T/py_dec.glb" "$TREES" >"$T/out" 2>&1
check "bake from bytes with a decorators file: obscura bake --decorators' bytes" \
    "cmp -s '$T/cli_dec.glb' '$T/py_dec.glb' && ! cmp -s '$T/cli_dec.glb' '$T/cli_bake.glb'"
py bake_out "http://127.0.0.1:$HP" "$FIX" "$T/py_out.glb" - >"$T/out" 2>&1
check "bake out= a path: the same file" "cmp -s '$T/cli_bake.glb' '$T/py_out.glb' && [ ! -e '$T/py_out.glb.part' ]"
py bake_badrules "http://127.0.0.1:$HP" "$FIX" "$T/x.glb" - >"$T/out" 2>&1
check "decorators that are not JSON: ObscuraError 400 bad_decorators ($(head -c 70 "$T/out"))" \
    "grep -q 'status=400 code=bad_decorators message=.*not JSON' '$T/out'"
py bake_failed "http://127.0.0.1:$HP" "$FIX" "$T/x.glb" - >"$T/out" 2>&1
check "a level without triangles: the job's failure as ObscuraError ($(head -c 90 "$T/out"))" \
    "grep -q 'status=None code=[a-z_]* message=.*triangles' '$T/out'"
py bake_binary "http://127.0.0.1:$HP" "$FIX" "$T/x.glb" - >"$T/out" 2>&1
check "bake over the binary protocol: ValueError, bake jobs are HTTP routes" \
    "grep -q 'ValueError: bake(): bake jobs are HTTP routes' '$T/out'"

echo "-- packaging and the example"
check "pyproject.toml names the module it packages" \
    "python3 -I -c 'import sys, tomllib; d = tomllib.load(open(\"clients/python/pyproject.toml\", \"rb\")); sys.exit(d[\"tool\"][\"setuptools\"][\"py-modules\"] != [\"obscura_client\"])' 2>/dev/null ||
     grep -q 'py-modules = \[\"obscura_client\"\]' clients/python/pyproject.toml"
check "the Blender example compiles, and imports only the standard library, bpy and the client" \
    "python3 -I -B -c \"import ast, sys; ast.parse(open(sys.argv[1]).read())\" clients/python/examples/blender_post_render.py &&
     ! grep -E '^(import|from) ' clients/python/examples/blender_post_render.py | grep -vqE '^(import|from) (bpy|os|sys|obscura_client)\\b'"

# pip install clients/python, offline (--no-build-isolation: the
# setuptools and wheel already there), into a folder of its own; with the
# first python3 that has pip, setuptools and wheel (Debian: python3-pip,
# python3-wheel)
PIPPY=""
for p in python3 /usr/bin/python3; do
    if "$p" -c 'import setuptools, wheel, pip' 2>/dev/null; then PIPPY=$p; break; fi
done
if [ -n "$PIPPY" ]; then
    cp -r clients/python "$T/pkg"
    rm -rf "$T/pkg/build" "$T/pkg/"*.egg-info
    "$PIPPY" -m pip install -q --no-build-isolation --no-deps --no-index --target "$T/site" "$T/pkg" >"$T/pip.log" 2>&1
    rc=$?
    "$PIPPY" -I -B -c 'import sys; sys.path.insert(0, sys.argv[1]); import obscura_client as oc
assert oc.__file__.startswith(sys.argv[1]), oc.__file__
open(sys.argv[4], "wb").write(oc.ao(sys.argv[2], server=sys.argv[3], fov_y=50, near=0.05, far=100,
                                    world_to_camera=sys.argv[5]))' "$T/site" "$R" "tcp://127.0.0.1:$TP" "$T/pip.exr" "$W2C" \
        >>"$T/pip.log" 2>&1
    check "pip install clients/python ($PIPPY): exit $rc, the installed module gives the CLI's bytes" \
        "[ $rc -eq 0 ] && cmp -s '$T/cli.exr' '$T/pip.exr'"
    [ -e "$T/pip.exr" ] || sed 's/^/       /' "$T/pip.log" | tail -5
else
    echo "  skip pip install: no python3 with pip, setuptools and wheel (Debian python3-pip, python3-wheel)"
fi

echo "-- warnings, the camera JSON, the CLI's header attributes"
# ObscuraWarning by default (no filter set), Answer.warnings, ObscuraError.warnings;
# Camera.from_json; the attribute names of an EXR's (single-part) header
cat > "$T/warn.py" <<'PYEOF'
import os, struct, sys
sys.path.insert(0, os.path.join(os.getcwd(), "clients", "python"))
import obscura_client as oc

def attrs(data):
    names, i = [], 8
    while data[i] != 0:
        name = data[i:data.index(b"\0", i)]
        i = data.index(b"\0", i + len(name) + 1) + 1
        (size,) = struct.unpack("<i", data[i:i + 4])
        i += 4 + size
        names.append(name.decode())
    return names

mode, server, src, cam_json, out = sys.argv[1:6]
if mode == "warn":
    a = oc.ao(src, server=server, camera=oc.Camera.from_json(cam_json), depth_mode="ndc")
    print("answer %s %d bytes, %d warnings: %s" % (type(a).__name__, len(a), len(a.warnings), " | ".join(a.warnings)))
elif mode == "clean":
    a = oc.ao(src, server=server, camera=oc.Camera.from_json(cam_json), out=out)
    print("clean %r %r" % (bytes(a), a.warnings))
elif mode == "error":
    try:
        oc.ao(src, server=server, camera=oc.Camera.from_json(cam_json), depth="NoSuchChannel")
    except oc.ObscuraError as e:
        print("error %s warnings %r" % (e.code, e.warnings))
elif mode == "asdict":
    import json
    a = oc.ao(src, server=server, camera=oc.Camera.from_json(json.load(open(cam_json))))
    b = oc.ao(src, server=server, camera=oc.Camera.from_json(cam_json))
    print("dict and path: %s" % ("same" if a == b else "differ"))
elif mode == "attrs":
    open(out, "wb").write(oc.ao(src, server=server, camera=oc.Camera.from_json(cam_json)))
    print(" ".join(sorted(attrs(open(out, "rb").read()))))
elif mode == "cliattrs":
    print(" ".join(sorted(attrs(open(src, "rb").read()))))
elif mode == "badjson":
    for bad in ({}, {"world_to_camera": [[1, 0, 0, 0]] * 4}, {"world_to_camera": [1] * 15, "fov_y_deg": 50}):
        try:
            oc.Camera.from_json(bad)
        except ValueError as e:
            print("ValueError: %s" % e)
PYEOF
pw() { python3 -I -B "$T/warn.py" "$@"; }
RCAM="$DATA/room_small.camera.json"
for url in "http://127.0.0.1:$HP" "unix:$SOCK" "tcp://127.0.0.1:$TP"; do
    pw warn "$url" "$R" "$RCAM" - >"$T/out" 2>"$T/err"
    check "${url%%:*} depth_mode=ndc: Answer.warnings name the cause and the flag ($(head -c 90 "$T/out"))" \
        "grep -q '^answer Answer [0-9]* bytes, 2 warnings: depth values up to .* impossible under --depth-mode ndc.*give --depth-mode planar' '$T/out'"
    check "${url%%:*}: each warning an ObscuraWarning on stderr by default, at the script's line" \
        "[ \$(grep -c 'warn.py:[0-9]*: ObscuraWarning: ' '$T/err') -eq 2 ] && grep -q 'ObscuraWarning: no pixel is occluded' '$T/err'"
    pw clean "$url" "$R" "$RCAM" "$T/clean.exr" >"$T/out" 2>"$T/err"
    check "${url%%:*} the right camera: no warning; out= gives b'' and [] ($(cat "$T/out"))" \
        "grep -qx \"clean b'' \\[\\]\" '$T/out' && [ ! -s '$T/err' ]"
done
pw error "http://127.0.0.1:$HP" "$R" "$RCAM" - >"$T/out" 2>&1
check "ObscuraError.warnings: a list ($(cat "$T/out"))" "grep -qx 'error missing_channel warnings \[\]' '$T/out'"
pw asdict "tcp://127.0.0.1:$TP" "$R" "$RCAM" - >"$T/out" 2>&1
check "Camera.from_json of a dict: the answer of the path's" "grep -qx 'dict and path: same' '$T/out'"
pw badjson - - - - >"$T/out" 2>&1
check "Camera.from_json refuses a camera without world_to_camera, without projection, of 15 numbers, naming it" \
    "grep -q 'world_to_camera: missing' '$T/out' && grep -q 'projection: missing' '$T/out' &&
     grep -q 'world_to_camera: expected 4 rows of 4 numbers' '$T/out'"
# the answer to a camera sent as query parameters carries the header
# attributes obscura ao --camera writes (worldToCamera, worldToNDC);
# obscura/params beside them names the parameters the daemon was sent
"$OBSCURA" ao "$R" --camera "$RCAM" -o "$T/cli_cam.exr" -q 2>/dev/null
pw cliattrs - "$T/cli_cam.exr" - - | tr ' ' '\n' | grep -vx 'obscura/params' >"$T/cli_attrs"
for url in "http://127.0.0.1:$HP" "unix:$SOCK"; do
    pw attrs "$url" "$R" "$RCAM" "$T/py_cam.exr" | tr ' ' '\n' | grep -vx 'obscura/params' >"$T/py_attrs"
    check "${url%%:*} Camera.from_json: the header attributes of obscura ao --camera, worldToCamera and worldToNDC among them" \
        "cmp -s '$T/cli_attrs' '$T/py_attrs' && grep -qx worldToNDC '$T/py_attrs' && grep -qx worldToCamera '$T/py_attrs'"
    check "${url%%:*} Camera.from_json: the pixels of obscura ao --camera" \
        "\"$OBSCURA\" compare '$T/cli_cam.exr' '$T/py_cam.exr' --channel-a AO.Y --channel-b AO.Y --mask none --json | grep -q '\"mae\": 0'"
done
pw cliattrs - "$T/cli.exr" - - >"$T/out"
check "obscura ao --fov-y --world-to-camera (the answers above, byte for byte) writes worldToCamera and worldToNDC" \
    "grep -q worldToCamera '$T/out' && grep -q worldToNDC '$T/out'"

kill "$PID_d" 2>/dev/null
wait "$PID_d" 2>/dev/null
[ $failed -ne 0 ] && tail -20 "$T/d.log" | sed 's/^/       /'
echo "e2e python client: $pass passed, $failed failed"
[ "$failed" -eq 0 ]
