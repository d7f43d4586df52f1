#!/bin/sh
# bench/BAKE.md, "Instanced trees": the vertex AO of polynesia's tree
# instances from the model of section 2.2 (local x global, eq 3) against
# its two halves alone (the global linear function, the local AO), the
# volume's AO that eq 3 fits (no model, per vertex), and
# against the reference, a bake that traces every tree instance's own
# surface samples in the level (--instanced off); RMS over the tree
# vertices of _AO (and of the long distance) and the seconds of each run.
# A second reference with another seed gives the reference's own noise.
#   bench/bake_instanced.sh [RAYS [VOLUME_RAYS [SPACING [SAMPLES_PER_FACE]]]]
#   (OBSCURA: the CLI; OBSCURA_SHARED_DATA: ../shared/data; LEVEL: under
#   its levels/, default 0ad/polynesia.glb; RUNS: which of reference
#   reference_seed2 product linear local volume, default all)
set -eu
OBSCURA=${OBSCURA:-build/obscura}
NAME=${LEVEL:-0ad/polynesia.glb}
LEVEL=${OBSCURA_SHARED_DATA:-../shared/data}/levels/$NAME
RUNS=${RUNS:-reference reference_seed2 product linear local volume}
RAYS=${1:-64}
VRAYS=${2:-128}
SPACING=${3:-2}
SPF=${4:-4}
if [ ! -f "$LEVEL" ]; then
    echo "bake_instanced bench: $LEVEL is absent (../shared, the shared levels): skipped"
    exit 0
fi
O=out/bake_instanced/$(basename "$NAME" .glb)
mkdir -p "$O"
run() { # name args...
    name=$1; shift
    case " $RUNS " in *" $name "*) ;; *) return 0 ;; esac
    echo "bake_instanced bench: $name: $*" >&2
    "$OBSCURA" bake "$LEVEL" -o "$O/$name.glb" --report "$O/$name.json" -q --rays "$RAYS" \
        --samples-per-face "$SPF" "$@"
}
run reference --instanced off
run reference_seed2 --instanced off --seed 2
V="--volume-rays $VRAYS --volume-spacing $SPACING"
run product $V
run linear $V --instanced-values linear
run local $V --instanced-values local
run volume $V --instanced-values volume
python3 - "$O" "$RAYS" "$VRAYS" "$SPACING" "$NAME" "$SPF" $RUNS <<'PY'
import array, json, struct, sys
o = sys.argv[1]
runs = sys.argv[7:]

def glb(path):
    data = open(path, "rb").read()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    buf = data[28 + jlen:]
    def acc(i):
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        x = array.array("f")
        x.frombytes(buf[v["byteOffset"]:v["byteOffset"] + 4 * a["count"]])
        return x
    out = {}
    for ni, n in enumerate(doc["nodes"]):
        if "mesh" not in n:
            continue
        for pi, p in enumerate(doc["meshes"][n["mesh"]]["primitives"]):
            at = p["attributes"]
            out[(ni, pi)] = (acc(at["_AO"]), acc(at["_AO_LONG"]), "_AO_LOCAL" in at)
    return out

ref = glb(o + "/reference.glb")
keys = [k for k, v in glb(o + "/product.glb").items() if v[2]]
def rms(name, which):
    g = glb(o + "/" + name + ".glb")
    s = n = 0
    for k in keys:
        for a, b in zip(g[k][which], ref[k][which]):
            s += (a - b) ** 2
            n += 1
    return (s / n) ** 0.5, n
def rep(name):
    return json.load(open(o + "/" + name + ".json"))
print("%s, %d tree primitives; %s rays per surface sample (%s samples per face), %s per "
      "volume point, spacing %s m" % (sys.argv[5], len(keys), sys.argv[2], sys.argv[6],
                                      sys.argv[3], sys.argv[4]))
print()
print("| tree vertex AO | RMS _AO vs reference | RMS _AO_LONG | bake (s) | instanced stages (s) |")
print("| --- | --- | --- | --- | --- |")
rows = [("local x global (eq 3), the paper's", "product"), ("(a) linear only: G fitted with L = 1", "linear"),
        ("(b) local only: L", "local"),
        ("no model: the volume's AO at the vertices (what eq 3 fits)", "volume"), ("reference, another seed (its noise)", "reference_seed2"),
        ("(c) reference: trees traced in place", "reference")]
for label, name in rows:
    if name not in runs:
        continue
    r = rep(name)
    sec = r["seconds"]
    inst = sec.get("local", 0) + sec.get("volume", 0) + sec.get("global", 0)
    e, n = rms(name, 0)
    el, _ = rms(name, 1)
    print("| %s | %.4f | %.4f | %.1f | %s |" % (label, e, el, sec["total"] - sec["load"] - sec["write"],
          "local %.2f, volume %.2f, eq 3 %.2f" % (sec["local"], sec["volume"], sec["global"]) if inst else "—"))
i = rep("product")["instanced"]
print()
print("product run: %d meshes baked alone, %d instances; volume %d bricks, %d points (%d inside "
      "geometry), %d rays; eq 3 residual against the volume's AO %.4f; %d tree vertices" % (
      i["meshes"], i["instances"], i["volume_bricks"], i["volume_points"], i["volume_points_inside"],
      i["volume_rays"], i["eq3_residual_rms"], n))
PY
