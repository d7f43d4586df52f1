#!/bin/sh
# bench/overhang.sh: the overhang case of bench/QUALITY.md ("What the
# estimator cannot see").  A floor (z = 0) under a table top without legs
# (1.2 x 1.2 m, 0.73 to 0.77 m high), seen from 3.5 m at 20 degrees down;
# for AO distances 0.25 to 2 m, the mean AO of the floor under the top and
# of a ring of floor 0.1 to 0.6 m outside its edge: the Embree reference
# (ray-traced, the ground truth), the default chain, vaopp with
# --ao-definition volume, and gtao.  Needs /usr/bin/python3 with numpy and
# OpenImageIO (tools/deps.sh) for the region means.
#
#   BUILD=build bench/overhang.sh
set -eu
BUILD=${BUILD:-build}
OBSCURA=$BUILD/obscura
OUT=out/overhang
PY=/usr/bin/python3
mkdir -p "$OUT"
"$PY" -c 'import numpy, OpenImageIO' 2>/dev/null ||
    { echo "overhang: $PY lacks numpy or OpenImageIO (tools/deps.sh)" >&2; exit 1; }

# the scene: the floor, then the top's six faces (counter-clockwise seen
# from outside)
awk 'BEGIN {
    n = 0
    quad(-6, -6, 0,  6, -6, 0,  6, 6, 0,  -6, 6, 0)
    x0 = -0.6; y0 = -0.6; z0 = 0.73; x1 = 0.6; y1 = 0.6; z1 = 0.77
    quad(x0, y0, z1, x1, y0, z1, x1, y1, z1, x0, y1, z1)
    quad(x0, y1, z0, x1, y1, z0, x1, y0, z0, x0, y0, z0)
    quad(x0, y0, z0, x1, y0, z0, x1, y0, z1, x0, y0, z1)
    quad(x1, y1, z0, x0, y1, z0, x0, y1, z1, x1, y1, z1)
    quad(x0, y1, z0, x0, y0, z0, x0, y0, z1, x0, y1, z1)
    quad(x1, y0, z0, x1, y1, z0, x1, y1, z1, x1, y0, z1)
}
function quad(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz) {
    printf "v %g %g %g\nv %g %g %g\nv %g %g %g\nv %g %g %g\n", ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz
    printf "f %d %d %d %d\n", n + 1, n + 2, n + 3, n + 4
    n += 4
}' >"$OUT/table.obj"
# eye (0, -3.2, 1.5) looking at (0, 0, 0.35), z up
cat >"$OUT/cam.json" <<'EOF'
{"width": 480, "height": 360, "fov_y_deg": 45, "near": 0.05, "far": 100,
 "world_to_camera": [[1, 0, 0, 0], [0, 0.338199, 0.941075, -0.329376],
                     [0, -0.941075, 0.338199, -3.518737], [0, 0, 0, 1]]}
EOF
"$OBSCURA" gbuffer "$OUT/table.obj" --camera "$OUT/cam.json" -o "$OUT/g.exr" 2>/dev/null
for D in 0.25 0.5 1 2; do
    "$OBSCURA" reference "$OUT/table.obj" --camera "$OUT/cam.json" --distance $D --spp 256 \
        -o "$OUT/ref_$D.exr" -q
    "$OBSCURA" ao "$OUT/g.exr" --camera "$OUT/cam.json" --radius $D -o "$OUT/default_$D.exr" -q
    "$OBSCURA" ao "$OUT/g.exr" --camera "$OUT/cam.json" --radius $D --ao-definition volume \
        -o "$OUT/volume_$D.exr" -q
    "$OBSCURA" ao "$OUT/g.exr" --camera "$OUT/cam.json" --radius $D --method gtao \
        -o "$OUT/gtao_$D.exr" -q
done
"$PY" - "$OUT" <<'EOF'
import sys
import numpy as np, OpenImageIO as oiio
out = sys.argv[1]
def load(path, chans):
    b = oiio.ImageBuf(path)
    names = list(b.spec().channelnames)
    a = b.get_pixels(oiio.FLOAT)
    return np.stack([a[:, :, names.index(c)] for c in chans], -1)
P = load(out + '/g.exr', ['P.X', 'P.Y', 'P.Z'])
Z = load(out + '/g.exr', ['Z'])[..., 0]
floor = (Z > 0) & (Z < 1e9) & (np.abs(P[..., 2]) < 1e-3)
cheb = np.maximum(np.abs(P[..., 0]), np.abs(P[..., 1]))
regions = [('floor under the top', floor & (cheb < 0.5)),
           ('floor 0.1-0.6 m outside its edge', floor & (cheb > 0.7) & (cheb < 1.2))]
print('| AO distance | region (pixels) | Embree | default | vaopp volume | gtao |')
print('|---|---|---|---|---|---|')
for D in ['0.25', '0.5', '1', '2']:
    ao = {k: load('%s/%s_%s.exr' % (out, k, D), ['AO.Y'])[..., 0]
          for k in ['ref', 'default', 'volume', 'gtao']}
    for name, m in regions:
        print('| %s m | %s (%d) | %.3f | %.3f | %.3f | %.3f |' % (
            D, name, m.sum(), ao['ref'][m].mean(), ao['default'][m].mean(),
            ao['volume'][m].mean(), ao['gtao'][m].mean()))
EOF
