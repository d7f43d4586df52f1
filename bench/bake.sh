#!/bin/sh
# The bake on the real levels (bench/BAKE.md): each run's --report into
# out/bake/, one markdown row per run.
#   bench/bake.sh [quick|full]      (OBSCURA: the CLI; OBSCURA_SHARED_DATA)
# quick: the TORCS tracks and polynesia with the defaults, the fit's
# variants on aalborg, battle_for_the_tiber at 32 rays and 1 sample per
# face; full: battle_for_the_tiber with the defaults too.
set -eu
OBSCURA=${OBSCURA:-build/obscura}
DATA=${OBSCURA_SHARED_DATA:-../shared/data}/levels
mode=${1:-quick}
if [ ! -d "$DATA" ]; then
    echo "bake bench: $DATA is absent (the shared levels): skipped"
    exit 0
fi
mkdir -p out/bake
row() { # name level args...
    name=$1; level=$2; shift 2
    "$OBSCURA" bake "$DATA/$level" -o "out/bake/$name.glb" --report "out/bake/$name.json" -q "$@"
    python3 - "out/bake/$name.json" "$name" "$*" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); c = r["counts"]; s = r["seconds"]; q = r["residual_rms"]
print("| %s | %s | %d | %d | %d | %d | %.1f | %.1f | %.2f | %.4f / %.4f | %.4f / %.4f | %.4f / %.4f | %.3f |" % (
    sys.argv[2], sys.argv[3] or "defaults", c["triangles"], c["samples"], c["samples_dropped_backface"],
    c["welded_vertices"], s["trace"], s["total"], r["rays_per_second"] / 1e6,
    q["least_squares"]["short"], q["least_squares"]["long"], q["face_mean"]["short"], q["face_mean"]["long"],
    q["point_sample"]["short"], q["point_sample"]["long"], r["ao"]["mean"]))
PY
}
echo "| run | options | triangles | samples | dropped | welded vertices | trace s | total s | Mrays/s | RMS LS short / long | RMS face mean | RMS point | mean _AO |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
row aalborg torcs/aalborg/aalborg.acc
row aalborg_analytic torcs/aalborg/aalborg.acc --mass analytic
row aalborg_alpha0 torcs/aalborg/aalborg.acc --alpha 0
row aalborg_nobackface torcs/aalborg/aalborg.acc --backface-limit 1
row forza torcs/forza/forza.acc
row polynesia 0ad/polynesia.glb
row tiber_quick 0ad/battle_for_the_tiber.glb --rays 32 --samples-per-face 1
if [ "$mode" = full ]; then
    row tiber 0ad/battle_for_the_tiber.glb
fi
