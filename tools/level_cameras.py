#!/usr/bin/env python3
"""Cameras over a level, made from its geometry alone (bench/bake_quality.sh,
tests/e2e/bake.sh).  Reads a .glb (the node graph's matrices and TRS
applied; the file's own binary chunk) with the standard library only and
writes N camera JSONs (obscura's format: world_to_camera rows, fov_y_deg,
near, far, width, height).

How the cameras are placed, +Y up (glTF's convention; the TORCS tracks
are +Y up too): the world box's horizontal extent is split into N equal
sectors of a circle of radius R = 0.25 x the horizontal diagonal around
the box's centre; camera i looks at the world vertex nearest (in x, z) to
the point of sector i on that circle, from a point D = 0.06 x the
diagonal back (horizontally, away from the centre, so it looks inwards)
and D / 2 above the target (27 degrees down).  Every camera
therefore sees geometry (its target is a vertex) from nearby, at the scale
of a player's view rather than the whole map's.

  tools/level_cameras.py LEVEL.glb OUTDIR N [WIDTH HEIGHT]
prints the paths written (OUTDIR/cam0.json, ...)."""
import json
import math
import struct
import sys


def mat_mul(a, b):
    return [sum(a[4 * r + k] * b[4 * k + c] for k in range(4)) for r in range(4) for c in range(4)]


def local_matrix(node):
    """Row-major 4x4, column vectors."""
    if "matrix" in node:
        m = node["matrix"]  # column-major
        return [m[4 * c + r] for r in range(4) for c in range(4)]
    t = node.get("translation", [0, 0, 0])
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    s = node.get("scale", [1, 1, 1])
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m = []
    for i in range(3):
        m += [r[i][0] * s[0], r[i][1] * s[1], r[i][2] * s[2], t[i]]
    return m + [0, 0, 0, 1]


def world_vertices(path):
    data = open(path, "rb").read()
    magic, version, _ = struct.unpack_from("<III", data, 0)
    if magic != 0x46546C67 or version != 2:
        sys.exit("%s: not a glTF 2.0 binary" % path)
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    blen = struct.unpack_from("<I", data, 20 + jlen)[0]
    buf = data[28 + jlen:28 + jlen + blen]

    def positions(i):
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        off = v.get("byteOffset", 0) + a.get("byteOffset", 0)
        stride = v.get("byteStride", 12)
        out = []
        for k in range(a["count"]):
            out.append(struct.unpack_from("<3f", buf, off + k * stride))
        return out

    pts = []
    ident = [1.0 if i % 5 == 0 else 0.0 for i in range(16)]
    stack = [(n, ident) for n in doc["scenes"][doc.get("scene", 0)]["nodes"]]
    while stack:
        n, parent = stack.pop()
        node = doc["nodes"][n]
        w = mat_mul(parent, local_matrix(node))
        if "mesh" in node:
            for p in doc["meshes"][node["mesh"]]["primitives"]:
                for x, y, z in positions(p["attributes"]["POSITION"]):
                    pts.append((w[0] * x + w[1] * y + w[2] * z + w[3],
                                w[4] * x + w[5] * y + w[6] * z + w[7],
                                w[8] * x + w[9] * y + w[10] * z + w[11]))
        stack += [(c, w) for c in node.get("children", [])]
    if not pts:
        sys.exit("%s: no vertices" % path)
    return pts


def look_at(eye, target):
    f = [target[k] - eye[k] for k in range(3)]
    fl = math.sqrt(sum(c * c for c in f))
    f = [c / fl for c in f]
    up = [0.0, 1.0, 0.0]
    r = [f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]]
    rl = math.sqrt(sum(c * c for c in r))
    r = [c / rl for c in r]
    u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
    rows = [r, u, [-c for c in f]]
    return [rows[i] + [-sum(rows[i][k] * eye[k] for k in range(3))] for i in range(3)] + \
        [[0.0, 0.0, 0.0, 1.0]]


def main():
    if len(sys.argv) not in (4, 6):
        sys.exit(__doc__)
    path, outdir, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
    width, height = (int(sys.argv[4]), int(sys.argv[5])) if len(sys.argv) == 6 else (320, 240)
    pts = world_vertices(path)
    lo = [min(p[k] for p in pts) for k in range(3)]
    hi = [max(p[k] for p in pts) for k in range(3)]
    c = [(lo[k] + hi[k]) / 2 for k in range(3)]
    diag = math.sqrt((hi[0] - lo[0]) ** 2 + (hi[2] - lo[2]) ** 2)
    R, D = 0.25 * diag, 0.06 * diag
    for i in range(n):
        a = 2 * math.pi * (i + 0.5) / n
        q = (c[0] + R * math.cos(a), c[2] + R * math.sin(a))
        t = min(pts, key=lambda p: (p[0] - q[0]) ** 2 + (p[2] - q[1]) ** 2)
        dx, dz = t[0] - c[0], t[2] - c[2]
        dl = math.hypot(dx, dz) or 1.0
        eye = (t[0] + D * dx / dl, t[1] + D / 2, t[2] + D * dz / dl)
        cam = {"width": width, "height": height, "fov_y_deg": 60.0,
               "near": max(D * 1e-3, 1e-3), "far": 4 * diag,
               "world_to_camera": look_at(eye, t),
               "made_by": "tools/level_cameras.py %s: camera %d of %d, target vertex %s"
                          % (path.split("/")[-1], i, n, [round(x, 3) for x in t])}
        out = "%s/cam%d.json" % (outdir, i)
        with open(out, "w") as f:
            json.dump(cam, f, indent=1)
        print(out)


if __name__ == "__main__":
    main()
