#!/usr/bin/env python3
"""Checks a .glb that obscura bake wrote, with the standard library only:
header and chunk lengths, every bufferView inside the buffer, every
accessor inside its view, POSITION min/max the true ones, material
indices in range, and per
primitive _AO, _AO_SHORT, _AO_LONG of POSITION's count with values in
[0, 1] and _AO = blend of the other two; for an instanced tree
(section 2.2: _AO_LOCAL and its node's extras "obscura_instanced"),
_AO = clamp(_AO_LOCAL x G(POSITION)) with G = global_ao instead (README's
bake section).  Usage: glb_check.py FILE [PRIMS [INSTANCED]] [--lods N [--lod-mean TOL]]
(PRIMS: the number of primitives expected, LODs' included, INSTANCED: of
instanced ones).  With --lods N: extensionsUsed names MSFT_lod, every node with a mesh lists
N LOD nodes in its MSFT_lod ids, each outside the scene's graph, with a
mesh of as many primitives, each with fewer or as many triangles as the
level above and the same _AO attributes (checked above); without it, no
node has MSFT_lod.  --lod-mean TOL: each level's mean _AO within TOL of
its node's mesh's."""
import array
import json
import struct
import sys


def main():
    data = open(sys.argv[1], "rb").read()
    magic, version, total = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67 and version == 2, "not glTF 2.0 binary"
    assert total == len(data), "length %d, file %d" % (total, len(data))
    jlen, jtype = struct.unpack_from("<II", data, 12)
    assert jtype == 0x4E4F534A and jlen % 4 == 0
    doc = json.loads(data[20:20 + jlen])
    blen, btype = struct.unpack_from("<II", data, 20 + jlen)
    assert btype == 0x004E4942 and blen % 4 == 0
    buf = data[28 + jlen:28 + jlen + blen]
    assert doc["buffers"][0]["byteLength"] <= blen
    for v in doc["bufferViews"]:
        assert v["byteOffset"] % 4 == 0 and v["byteOffset"] + v["byteLength"] <= blen

    def values(i):
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        n = {"SCALAR": 1, "VEC3": 3}[a["type"]]
        assert a["count"] * n * 4 <= v["byteLength"]
        x = array.array("f" if a["componentType"] == 5126 else "I")
        x.frombytes(buf[v["byteOffset"]:v["byteOffset"] + a["count"] * n * 4])
        return a, x, n

    blend = None
    prims = instanced = 0
    coef = {}  # (mesh, primitive) -> global_ao of the node holding it
    for n in doc["nodes"]:
        for e in n.get("extras", {}).get("obscura_instanced", []) if isinstance(
                n.get("extras"), dict) else []:
            for key in ("global_ao", "global_ao_short", "global_ao_long"):
                assert len(e[key]) == 4, key
            coef[(n["mesh"], e["primitive"])] = e["global_ao"]
    for mi, mesh in enumerate(doc["meshes"]):
        for pi, p in enumerate(mesh["primitives"]):
            at = p["attributes"]
            a, pos, _ = values(at["POSITION"])
            for k in range(3):
                col = pos[k::3]
                assert abs(min(col) - a["min"][k]) < 1e-6 and abs(max(col) - a["max"][k]) < 1e-6
            nv = a["count"]
            if "material" in p:
                assert 0 <= p["material"] < len(doc.get("materials", [])), "material index"
            _, idx, _ = values(p["indices"])
            assert len(idx) % 3 == 0 and max(idx) < nv
            vals = {}
            for name in ("_AO", "_AO_SHORT", "_AO_LONG"):
                acc, x, n = values(at[name])
                assert n == 1 and acc["count"] == nv, name
                assert 0.0 <= min(x) and max(x) <= 1.0, name
                vals[name] = x
            if "_AO_LOCAL" in at:
                _, loc, _ = values(at["_AO_LOCAL"])
                g = coef[(mi, pi)]
                for v in range(nv):
                    want = loc[v] * (g[0] + g[1] * pos[3 * v] + g[2] * pos[3 * v + 1] +
                                     g[3] * pos[3 * v + 2])
                    want = min(1.0, max(0.0, want))
                    assert abs(vals["_AO"][v] - want) < 1e-4, "_AO = _AO_LOCAL x G"
                instanced += 1
                prims += 1
                continue
            assert (mi, pi) not in coef, "coefficients without _AO_LOCAL"
            for ao, s, l in zip(vals["_AO"], vals["_AO_SHORT"], vals["_AO_LONG"]):
                if abs(s - l) > 1e-3:  # the blend, where it is determined
                    b = (ao - l) / (s - l)
                    blend = b if blend is None else blend
                    assert abs(b - blend) < 2e-3 or abs(ao - (blend * s + (1 - blend) * l)) < 1e-5
            prims += 1
    counts = sys.argv[2:sys.argv.index("--lods")] if "--lods" in sys.argv else sys.argv[2:]
    if len(counts) > 0:
        assert prims == int(counts[0]), "%d primitives" % prims
    if len(counts) > 1:
        assert instanced == int(counts[1]), "%d instanced primitives" % instanced
    nodes = doc["nodes"]
    seen = set(doc["scenes"][0]["nodes"])
    for n in nodes:
        seen.update(n.get("children", []))
    lods = int(sys.argv[sys.argv.index("--lods") + 1]) if "--lods" in sys.argv else 0
    lod_nodes = set()

    def mean_ao(mesh):
        v = [x for p in doc["meshes"][mesh]["primitives"] for x in values(p["attributes"]["_AO"])[1]]
        return sum(v) / len(v)

    lod_tol = float(sys.argv[sys.argv.index("--lod-mean") + 1]) if "--lod-mean" in sys.argv else None

    def tris(mesh):
        return [values(p["indices"])[0]["count"] // 3 for p in doc["meshes"][mesh]["primitives"]]

    for i, n in enumerate(nodes):
        ids = n.get("extensions", {}).get("MSFT_lod", {}).get("ids")
        if not lods:
            assert ids is None, "node %d: MSFT_lod without --lods" % i
            continue
        if i not in seen:  # a LOD node itself
            assert ids is None, "LOD node %d: MSFT_lod of its own" % i
            continue
        if "mesh" not in n:
            assert ids is None, "node %d: MSFT_lod without a mesh" % i
            continue
        assert ids is not None and len(ids) == lods, "node %d: MSFT_lod ids %s" % (i, ids)
        above = tris(n["mesh"])
        for k, j in enumerate(ids):
            assert j not in seen, "LOD node %d is in the scene's graph" % j
            lod = nodes[j]
            assert lod["name"] == "%s_LOD%d" % (n["name"], k + 1), lod["name"]
            assert lod.get("matrix") == n.get("matrix") and "children" not in lod
            t = tris(lod["mesh"])
            assert len(t) == len(above) and all(0 < a <= b for a, b in zip(t, above)), (t, above)
            above = t
            lod_nodes.add(j)
            if lod_tol is not None:  # a level shows the AO of the mesh it stands for
                d = abs(mean_ao(lod["mesh"]) - mean_ao(n["mesh"]))
                assert d < lod_tol, "node %d LOD %d: mean _AO %.3f from the full's" % (i, k + 1, d)
    if lods:
        assert "MSFT_lod" in doc.get("extensionsUsed", []), "extensionsUsed"
        assert lod_nodes, "no LOD node"
    seen |= lod_nodes
    assert len(seen) == len(nodes), "every node reachable"
    print("glb ok: %d nodes (%d LOD), %d primitives (%d instanced), blend %s" % (
        len(nodes), len(lod_nodes), prims, instanced, "%.4f" % blend if blend is not None else "-"))


main()
