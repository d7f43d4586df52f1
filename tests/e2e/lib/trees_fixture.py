#!/usr/bin/env python3
"""Writes a tiny glTF 2.0 binary level with instanced trees, for
tests/e2e/bake.sh (section 2.2's instanced decorators): a ground of
8 x 8 quads (40 m, y = -0.05, facing +y), a roof (8 m square, y = 2.6,
facing down) over x = -10, and one tree mesh (two crossed vertical
cards, 1 x 2 m, double-sided) held by 4 nodes with extras
{"class": "tree"}: one under the roof, three in the open.  Y up, as
glTF.  Usage: trees_fixture.py OUT.glb"""
import json
import struct
import sys


def grid(o, u, v, nu, nv):
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    ln = sum(c * c for c in n) ** 0.5
    n = [c / ln for c in n]
    pos, nrm, idx = [], [], []
    for j in range(nv + 1):
        for i in range(nu + 1):
            pos += [o[c] + u[c] * i / nu + v[c] * j / nv for c in range(3)]
            nrm += n
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            b, c, d = a + 1, a + nu + 2, a + nu + 1
            idx += [a, b, c, a, c, d]
    return pos, nrm, idx


def join(*parts):
    pos, nrm, idx = [], [], []
    for p, n, i in parts:
        base = len(pos) // 3
        pos += p
        nrm += n
        idx += [k + base for k in i]
    return pos, nrm, idx


def main():
    ground = grid([-20, -0.05, 20], [40, 0, 0], [0, 0, -40], 8, 8)  # u x v = +y
    roof = grid([-14, 2.6, -4], [8, 0, 0], [0, 0, 8], 4, 4)  # u x v = -y
    tree = join(grid([-0.5, 0, 0], [1, 0, 0], [0, 2, 0], 2, 4),
                grid([0, 0, 0.5], [0, 0, -1], [0, 2, 0], 2, 4))
    meshes = [("ground", ground, 0), ("roof", roof, 0), ("palm", tree, 1)]
    buf = bytearray()
    views, accessors, gmeshes = [], [], []

    def add(data, fmt, target):
        off = len(buf)
        buf.extend(struct.pack("<%d%s" % (len(data), fmt), *data))
        while len(buf) % 4:
            buf.append(0)
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(data) * 4,
                      "target": target})
        return len(views) - 1

    for name, (pos, nrm, idx), mat in meshes:
        nv = len(pos) // 3
        mn = [min(pos[c::3]) for c in range(3)]
        mx = [max(pos[c::3]) for c in range(3)]
        accessors.append({"bufferView": add(pos, "f", 34962), "componentType": 5126,
                          "count": nv, "type": "VEC3", "min": mn, "max": mx})
        accessors.append({"bufferView": add(nrm, "f", 34962), "componentType": 5126,
                          "count": nv, "type": "VEC3"})
        accessors.append({"bufferView": add(idx, "I", 34963), "componentType": 5125,
                          "count": len(idx), "type": "SCALAR"})
        a = len(accessors) - 3
        gmeshes.append({"name": name, "primitives": [{
            "attributes": {"POSITION": a, "NORMAL": a + 1}, "indices": a + 2,
            "material": mat, "mode": 4}]})
    tree_extras = {"class": "tree", "kind": "tree"}
    nodes = [{"name": "ground", "mesh": 0}, {"name": "roof", "mesh": 1},
             {"name": "palm_under_roof", "mesh": 2, "translation": [-10.13, 0, 0.21],
              "extras": tree_extras},
             {"name": "palm_open_a", "mesh": 2, "translation": [10.17, 0, 0.23], "extras": tree_extras},
             {"name": "palm_open_b", "mesh": 2, "translation": [10.11, 0, 8.29], "extras": tree_extras},
             {"name": "palm_open_c", "mesh": 2, "translation": [0.19, 0, -10.27],
              "extras": tree_extras}]
    doc = {"asset": {"version": "2.0", "generator": "obscura tests/e2e/lib/trees_fixture.py"},
           "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
           "meshes": gmeshes, "accessors": accessors, "bufferViews": views,
           "buffers": [{"byteLength": len(buf)}],
           "materials": [{"name": "opaque"}, {"name": "leaves", "doubleSided": True}]}
    js = json.dumps(doc).encode()
    while len(js) % 4:
        js += b" "
    total = 12 + 8 + len(js) + 8 + len(buf)
    with open(sys.argv[1], "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, total))
        f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        f.write(struct.pack("<II", len(buf), 0x004E4942) + bytes(buf))


main()
