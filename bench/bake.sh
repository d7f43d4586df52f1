#!/bin/sh
# The bake on the real levels (bench/BAKE.md): each run's --report into
# out/bake/, then two markdown tables from the reports: quality (RMS of
# the fit and the two baselines at held-out samples) and stage times.
#   bench/bake.sh [quick|full]      (OBSCURA: the CLI; OBSCURA_SHARED_DATA)
# quick: the TORCS tracks and polynesia with the defaults and --holdout 1,
# the fit's variants on aalborg, battle_for_the_tiber at 32 rays and 1
# sample per face; full: battle_for_the_tiber with the defaults too.
set -eu
OBSCURA=${OBSCURA:-build/obscura}
DATA=${OBSCURA_SHARED_DATA:-../shared/data}/levels
mode=${1:-quick}
if [ ! -d "$DATA" ]; then
    echo "bake bench: $DATA is absent (the shared levels): skipped"
    exit 0
fi
mkdir -p out/bake
runs=""
run() { # name level args...
    name=$1; level=$2; shift 2
    echo "bake bench: $name: $level $*" >&2
    "$OBSCURA" bake "$DATA/$level" -o "out/bake/$name.glb" --report "out/bake/$name.json" -q "$@"
    runs="$runs $name"
}
run aalborg torcs/aalborg/aalborg.acc --holdout 1
run aalborg_alpha0 torcs/aalborg/aalborg.acc --holdout 1 --alpha 0
run aalborg_alpha0.1 torcs/aalborg/aalborg.acc --holdout 1 --alpha 0.1
run aalborg_alpha10 torcs/aalborg/aalborg.acc --holdout 1 --alpha 10
run aalborg_analytic torcs/aalborg/aalborg.acc --holdout 1 --mass analytic
run aalborg_nobackface torcs/aalborg/aalborg.acc --holdout 1 --backface-limit 1
run forza torcs/forza/forza.acc --holdout 1
run polynesia 0ad/polynesia.glb --holdout 1
run tiber_quick 0ad/battle_for_the_tiber.glb --rays 32 --samples-per-face 1
if [ "$mode" = full ]; then
    run tiber 0ad/battle_for_the_tiber.glb
fi
python3 - $runs <<'PY'
import json, sys
rs = [(n, json.load(open("out/bake/%s.json" % n))) for n in sys.argv[1:]]
def opts(r):
    p = r["params"]
    return "alpha %g, mass %s, backface %g, %d rays, %g/face" % (
        p["alpha"], p["mass"], p["backface_limit"], p["rays"], p["samples_per_face"])
print("| run | options | samples | dropped | held-out samples | LS short / long | face mean | point | mean _AO |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for n, r in rs:
    h = r.get("holdout_rms")
    if not h:
        continue
    c = r["counts"]
    f = lambda k: "%.4f / %.4f" % (h[k]["short"], h[k]["long"])
    print("| %s | %s | %d | %d | %d | %s | %s | %s | %.3f |" % (
        n, opts(r), c["samples"], c["samples_dropped_backface"], h["samples"],
        f("least_squares"), f("face_mean"), f("point_sample"), r["ao"]["mean"]))
print()
st = ["load", "flatten", "samples", "bvh", "trace", "weld", "assemble", "solve", "instanced", "write", "total"]
print("| run | triangles | welded vertices | rays | " + " | ".join(st) + " | Mrays/s |")
print("| --- " * (len(st) + 5) + "|")
for n, r in rs:
    c, s = r["counts"], r["seconds"]
    # instanced trees (section 2.2): local AO, volume, eq 3
    s["instanced"] = s.get("local", 0) + s.get("volume", 0) + s.get("global", 0)
    print("| %s | %d | %d | %.3g | %s | %.2f |" % (
        n, c["triangles"], c["welded_vertices"], c["rays"],
        " | ".join("%.2f" % s[k] for k in st), r["rays_per_second"] / 1e6))
PY
