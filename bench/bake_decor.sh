#!/bin/sh
# Decorators on the real levels (bench/BAKE.md, "Decorators"): the fog
# proxies of section 2.1 (and the trees' semi-transparency, and leaving
# the objects out) against tracing their real geometry.  For each level a
# bake with the objects as ordinary opaque geometry (the reference), the
# same with another seed (the Monte Carlo noise floor), then the objects
# as shrubs (fog boxes), as trees (semi-transparent) for the TORCS cards,
# and left out (class small: they occlude nothing; their own vertices get
# the 2.2.1 scalar).  Error: the RMS over the vertices of the other
# (non-decorator) geometry of _AO against the reference bake; times from
# each run's --report.
#   bench/bake_decor.sh [quick|full]   (OBSCURA: the CLI; OBSCURA_SHARED_DATA)
# quick: polynesia (bushes), aalborg and forza (tree cards) at 32 rays;
# full adds battle_for_the_tiber (bushes) at 16 rays, 1 sample per face.
set -eu
OBSCURA=${OBSCURA:-build/obscura}
DATA=${OBSCURA_SHARED_DATA:-../shared/data}/levels
mode=${1:-quick}
if [ ! -d "$DATA" ]; then
    echo "bake decorators bench: $DATA is absent (the shared levels): skipped, nothing measured"
    exit 0
fi
OUT=out/bake_decor
mkdir -p "$OUT"
# The decorator files: 0 A.D.'s bushes by name (their nodes are named after
# the actor, props/flora/bush_*), TORCS' cards from trees.json.
python3 - "$DATA" "$OUT" <<'PY'
import json, sys
data, out = sys.argv[1:]
for c in ("shrub", "small"):
    json.dump({"decorators": [{"match": "*bush*", "class": c}]}, open("%s/bush_%s.json" % (out, c), "w"))
for t in ("aalborg", "forza"):
    names = sorted({e["name"] for e in json.load(open("%s/torcs/%s/trees.json" % (data, t)))["trees"]})
    for c in ("tree", "shrub", "small"):
        json.dump({"decorators": [{"name": n, "class": c} for n in names]},
                  open("%s/%s_%s.json" % (out, t, c), "w"))
PY
runs=""
run() { # name level args...
    name=$1; level=$2; shift 2
    echo "bake decorators bench: $name: $level $*" >&2
    "$OBSCURA" bake "$DATA/$level" -o "$OUT/$name.glb" --report "$OUT/$name.json" -q "$@"
    runs="$runs $name"
}
P="--rays 32"
run polynesia_real 0ad/polynesia.glb $P --decorator-source off
run polynesia_real_seed2 0ad/polynesia.glb $P --decorator-source off --seed 2
run polynesia_fog 0ad/polynesia.glb $P --decorator-source file --decorators "$OUT/bush_shrub.json"
run polynesia_fog_d0.3 0ad/polynesia.glb $P --decorator-source file --decorators "$OUT/bush_shrub.json" --shrub-density 0.3
run polynesia_fog_d3 0ad/polynesia.glb $P --decorator-source file --decorators "$OUT/bush_shrub.json" --shrub-density 3
run polynesia_none 0ad/polynesia.glb $P --decorator-source file --decorators "$OUT/bush_small.json"
for t in aalborg forza; do
    run ${t}_real torcs/$t/$t.acc $P --decorator-source off
    run ${t}_real_seed2 torcs/$t/$t.acc $P --decorator-source off --seed 2
    run ${t}_transparent torcs/$t/$t.acc $P --decorator-source file --decorators "$OUT/${t}_tree.json"
    run ${t}_fog torcs/$t/$t.acc $P --decorator-source file --decorators "$OUT/${t}_shrub.json"
    run ${t}_none torcs/$t/$t.acc $P --decorator-source file --decorators "$OUT/${t}_small.json"
done
if [ "$mode" = full ]; then
    Q="--rays 16 --samples-per-face 1"
    run tiber_real 0ad/battle_for_the_tiber.glb $Q --decorator-source off
    run tiber_real_seed2 0ad/battle_for_the_tiber.glb $Q --decorator-source off --seed 2
    run tiber_fog 0ad/battle_for_the_tiber.glb $Q --decorator-source file --decorators "$OUT/bush_shrub.json"
    run tiber_none 0ad/battle_for_the_tiber.glb $Q --decorator-source file --decorators "$OUT/bush_small.json"
fi
python3 - "$OUT" $runs <<'PY'
import json, struct, sys
import fnmatch
out, runs = sys.argv[1], sys.argv[2:]

def glb_ao(path):
    """{(node index): [_AO of its vertices]} of a baked .glb."""
    b = open(path, "rb").read()
    n = struct.unpack("<I", b[12:16])[0]
    j = json.loads(b[20:20 + n])
    bin0 = 20 + n + 8
    res = {}
    for i, nd in enumerate(j["nodes"]):
        if "mesh" not in nd:
            continue
        vals = []
        for pr in j["meshes"][nd["mesh"]]["primitives"]:
            a = j["accessors"][pr["attributes"]["_AO"]]
            v = j["bufferViews"][a["bufferView"]]
            o = bin0 + v.get("byteOffset", 0) + a.get("byteOffset", 0)
            vals += struct.unpack("<%df" % a["count"], b[o:o + 4 * a["count"]])
        res[i] = (nd.get("name", ""), vals)
    return res

level = lambda r: r.split("_")[0]
ref = {}
rows = []
for r in runs:
    rep = json.load(open("%s/%s.json" % (out, r)))
    ao = glb_ao("%s/%s.glb" % (out, r))
    rows.append((r, rep, ao))
    if r.endswith("_real"):
        ref[level(r)] = ao
# which nodes are the objects under test: 0 A.D. bushes by name, TORCS cards by trees.json
def is_object(lv, name):
    if lv in ("polynesia", "tiber"):
        return fnmatch.fnmatch(name, "*bush*")
    return name in objs[lv]
objs = {}
for lv in ("aalborg", "forza"):
    try:
        objs[lv] = {d["name"] for d in json.load(open("%s/%s_tree.json" % (out, lv)))["decorators"]}
    except OSError:
        objs[lv] = set()
print("| run | decorator nodes (shrub / tree / small) | vertices compared | bvh s | trace s | total s | RMS _AO vs real | max abs | mean _AO (compared) |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for r, rep, ao in rows:
    lv = level(r)
    base = ref[lv]
    s2 = n = 0
    mx = 0.0
    mean = 0.0
    for i, (name, vals) in ao.items():
        if is_object(lv, name):
            continue
        for a, b in zip(vals, base[i][1]):
            s2 += (a - b) ** 2
            mx = max(mx, abs(a - b))
            mean += a
            n += 1
    d = rep["decorator_nodes"]
    sec = rep["seconds"]
    print("| %s | %d / %d / %d | %d | %.2f | %.2f | %.2f | %.4f | %.3f | %.4f |" % (
        r, d["shrub"], d["tree"], d["small"], n, sec["bvh"], sec["trace"], sec["total"],
        (s2 / n) ** 0.5 if n else 0.0, mx, mean / n if n else 0.0))
PY
