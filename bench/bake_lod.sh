#!/bin/sh
# LODs of the bake (bench/BAKE.md, "LODs"): polynesia baked with --lods 2
# --lod-check 1, each level's resampled fit and the vertex baseline
# (sampling at the LOD's vertices) against the bake made directly on the
# LOD geometry (the LOD's samples traced there and fitted), the lod
# stage's times; then, with TIBER=1, battle_for_the_tiber with --lods 2 at
# Table 1's quick column's parameters (32 rays, 1 sample per face) for its
# "LOD resample and solve" row.
#   bench/bake_lod.sh        (OBSCURA: the CLI; OBSCURA_SHARED_DATA;
#                             RAYS, default 64)
set -eu
OBSCURA=${OBSCURA:-build/obscura}
DATA=${OBSCURA_SHARED_DATA:-../shared/data}/levels
RAYS=${RAYS:-64}
mkdir -p out/bake_lod
runs=""
run() { # name level args...
    name=$1; level=$2; shift 2
    if [ ! -f "$DATA/$level" ]; then
        echo "bake_lod bench: $DATA/$level is absent (shared data): $name skipped" >&2
        return 0
    fi
    echo "bake_lod bench: $name: $level $*" >&2
    "$OBSCURA" bake "$DATA/$level" -o "out/bake_lod/$name.glb" --report "out/bake_lod/$name.json" \
        -q "$@"
    runs="$runs $name"
}
run polynesia 0ad/polynesia.glb --rays "$RAYS" --lods 2 --lod-check 1
if [ "${TIBER:-0}" = 1 ]; then
    run tiber_quick_lods 0ad/battle_for_the_tiber.glb --rays 32 --samples-per-face 1 --lods 2
fi
[ -n "$runs" ] || exit 0
python3 - $runs <<'PY'
import json, sys
for n in sys.argv[1:]:
    r = json.load(open("out/bake_lod/%s.json" % n))
    p, c, s, lod = r["params"], r["counts"], r["seconds"], r["lods"]
    print("\n%s: %d triangles, %d welded vertices, %d samples, %d rays per sample, %g samples per face"
          % (n, c["triangles"], c["welded_vertices"], c["samples"], p["rays"], p["samples_per_face"]))
    f = lambda d: "%.4f / %.4f" % (d["short"], d["long"])
    print("\n| level | triangles | welded vertices | samples | fit vs resampled | vertex sampling vs resampled |"
          + (" held out: fit | held out: vertex sampling | fit vs direct bake | vertex sampling vs direct bake"
             " | resampled vs direct bake | direct bake in-sample |" if p["lod_check"] else ""))
    print("| --- " * (12 if p["lod_check"] else 6) + "|")
    print("| full | %d | %d | %d | %s | — |" % (c["triangles"], c["welded_vertices"], c["samples"],
                                             f(r["residual_rms"]["least_squares"]))
          + (" — | — | — | — | — | — |" if p["lod_check"] else ""))
    for l in lod["per_level"]:
        row = "| %d | %d | %d | %d | %s | %s |" % (l["level"], l["triangles"], l["welded_vertices"], l["samples"],
                                                f(l["resampled_rms"]["least_squares"]),
                                                f(l["resampled_rms"]["vertex_sample"]))
        if p["lod_check"]:
            d, h = l["direct_bake_rms"], l["holdout_resampled_rms"]
            row += " %s | %s |" % (f(h["least_squares"]), f(h["vertex_sample"]))
            row += " %s | %s | %s | %s |" % (f(d["least_squares"]), f(d["vertex_sample"]), f(d["resampled"]),
                                             f(d["direct_in_sample"]))
        print(row)
    ls = lod["seconds"]
    print("\nseconds: load %.2f, flatten %.2f, samples %.2f, bvh %.2f, trace %.2f, weld %.2f, assemble %.2f, "
          "solve %.2f, lod %.2f (simplify %.2f, resample %.2f, weld + fit %.2f, direct bake %.2f), write %.2f, total %.2f"
          % (s["load"], s["flatten"], s["samples"], s["bvh"], s["trace"], s["weld"], s["assemble"], s["solve"],
             s["lod"], ls["simplify"], ls["resample"], ls["fit"], ls["check"], s["write"], s["total"]))
PY
