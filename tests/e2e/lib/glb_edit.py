#!/usr/bin/env python3
"""Rewrites the JSON chunk of a .glb (tests/e2e/bake.sh), the binary chunk
kept: glb_edit.py IN OUT EDIT, EDIT one of
  trs     the root nodes get translation (10, 2, -5), rotation 90 degrees
          about +Y and scale (2, 2, 2) as TRS
  matrix  the same transform as a column-major matrix
  noao    every _AO attribute renamed (no baked values left)
  lodmove the first MSFT_lod level node moved (translation 1, 0, 0): a LOD
          against its node's transform
  lodprims the first MSFT_lod level node's mesh loses a primitive
  lodcount the first MSFT_lod level's POSITION accessor claims 10^9
          vertices, beyond its view"""
import json
import math
import struct
import sys


def main():
    src, dst, edit = sys.argv[1:4]
    data = open(src, "rb").read()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    rest = data[20 + jlen:]
    s = math.sqrt(0.5)
    # R_y(90): x -> -z, z -> x; times scale 2; then the translation
    m = [0, 0, -2, 0, 0, 2, 0, 0, 2, 0, 0, 0, 10, 2, -5, 1]  # column-major
    lods = [n["extensions"]["MSFT_lod"]["ids"][0] for n in doc["nodes"]
            if "MSFT_lod" in n.get("extensions", {})]
    if edit == "lodmove":
        doc["nodes"][lods[0]]["translation"] = [1, 0, 0]
    if edit == "lodprims":
        # a mesh of one primitive fewer, of its own
        mesh = dict(doc["meshes"][doc["nodes"][lods[0]]["mesh"]])
        mesh["primitives"] = mesh["primitives"][:-1] or []
        doc["meshes"].append(mesh)
        doc["nodes"][lods[0]]["mesh"] = len(doc["meshes"]) - 1
    if edit == "lodcount":
        prim = doc["meshes"][doc["nodes"][lods[0]]["mesh"]]["primitives"][0]
        doc["accessors"][prim["attributes"]["POSITION"]]["count"] = 10 ** 9
    for r in doc["scenes"][doc.get("scene", 0)]["nodes"] if edit in ("trs", "matrix") else []:
        n = doc["nodes"][r]
        n.pop("matrix", None)
        if edit == "trs":
            n.update(translation=[10, 2, -5], rotation=[0, s, 0, s], scale=[2, 2, 2])
        elif edit == "matrix":
            n["matrix"] = m
    if edit == "noao":
        for mesh in doc["meshes"]:
            for p in mesh["primitives"]:
                a = p["attributes"]
                if "_AO" in a:
                    a["_XO"] = a.pop("_AO")
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(j) + len(rest)) + \
        struct.pack("<II", len(j), 0x4E4F534A) + j + rest
    open(dst, "wb").write(out)


if __name__ == "__main__":
    main()
