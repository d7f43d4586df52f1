#!/usr/bin/env python3
"""A dynamic object put into a baked level (tests/e2e/dynamic.sh): a cube
without _AO added to a .glb as a new root node, and a camera looking at
it, the binary chunk extended.

    glb_dynamic.py IN.glb OUT.glb CAM.json NAME X,Y,Z SIZE [extras]

`extras`: the node gets glTF extras {"obscura_dynamic": true}.  The
camera (obscura's camera JSON, 160x120) looks at the cube from above and
aside, 3.5 sizes away."""
import json
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "tools"))
from level_cameras import look_at  # noqa: E402

FACES = [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
         ((0, 1, 0), (0, 0, 1), (1, 0, 0)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
         ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (0, 1, 0), (1, 0, 0))]


def cube(size):
    """24 vertices (4 a face, its normal), 12 counter-clockwise triangles."""
    pos, nrm, idx = [], [], []
    h = size / 2
    for n, u, v in FACES:
        base = len(pos)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            pos.append([h * (n[a] + su * u[a] + sv * v[a]) for a in range(3)])
            nrm.append(list(n))
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, idx


def main():
    src, dst, camp, name, at, size = sys.argv[1:7]
    extras = len(sys.argv) > 7 and sys.argv[7] == "extras"
    c = [float(x) for x in at.split(",")]
    size = float(size)
    data = open(src, "rb").read()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    blen = struct.unpack_from("<I", data, 20 + jlen)[0]
    binc = bytearray(data[28 + jlen:28 + jlen + blen])
    binc += b"\0" * (-len(binc) % 4)
    pos, nrm, idx = cube(size)
    views, accs = doc.setdefault("bufferViews", []), doc.setdefault("accessors", [])

    def add(raw, count, kind, ctype, extra=None):
        views.append({"buffer": 0, "byteOffset": len(binc), "byteLength": len(raw)})
        binc.extend(raw)
        binc.extend(b"\0" * (-len(binc) % 4))
        a = {"bufferView": len(views) - 1, "count": count, "type": kind, "componentType": ctype}
        a.update(extra or {})
        accs.append(a)
        return len(accs) - 1

    lo = [min(p[a] for p in pos) for a in range(3)]
    hi = [max(p[a] for p in pos) for a in range(3)]
    ap = add(b"".join(struct.pack("<3f", *p) for p in pos), 24, "VEC3", 5126, {"min": lo, "max": hi})
    an = add(b"".join(struct.pack("<3f", *n) for n in nrm), 24, "VEC3", 5126)
    ai = add(struct.pack("<%dI" % len(idx), *idx), len(idx), "SCALAR", 5125)
    doc.setdefault("meshes", []).append(
        {"name": name + "_mesh", "primitives": [{"attributes": {"POSITION": ap, "NORMAL": an},
                                                 "indices": ai}]})
    node = {"name": name, "mesh": len(doc["meshes"]) - 1, "translation": c}
    if extras:
        node["extras"] = {"obscura_dynamic": True}
    doc["nodes"].append(node)
    doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)
    doc["buffers"][0]["byteLength"] = len(binc)
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(j) + 8 + len(binc)) + \
        struct.pack("<II", len(j), 0x4E4F534A) + j + struct.pack("<II", len(binc), 0x004E4942) + binc
    open(dst, "wb").write(out)
    eye = [c[0] + 2.0 * size, c[1] + 2.5 * size, c[2] + 1.5 * size]
    cam = {"width": 160, "height": 120, "fov_y_deg": 50.0, "near": 0.01 * size,
           "far": 1e4 * size, "world_to_camera": look_at(eye, c),
           "made_by": "tests/e2e/lib/glb_dynamic.py: looking at %s" % name}
    json.dump(cam, open(camp, "w"), indent=1)


main()
