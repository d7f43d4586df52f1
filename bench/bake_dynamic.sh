#!/bin/sh
# bench/BAKE.md, "Dynamic objects": obscura bake-dynamic on two levels of
# ../shared/data/levels with few rays (128 per valid point, 256 per probe
# point: the defaults are 1024), the report of each run in
# out/bake_dynamic/, the tables on stdout.
#
#   make -j2 all && bench/bake_dynamic.sh
set -eu
OBSCURA=${OBSCURA:-build/obscura}
SHARED=${OBSCURA_SHARED_DATA:-../shared/data}
OUT=out/bake_dynamic
mkdir -p "$OUT"
COMMON="--rays 128 --holdout 0.2 --paths 100 --path-steps 64 --path-rays 256 --tau 4 --threads 2 -q"

run() { # NAME LEVEL ARGS...
    name=$1; level=$2; shift 2
    "$OBSCURA" bake-dynamic "$level" -o "$OUT/$name.model.json" --report "$OUT/$name.json" $COMMON "$@"
}

LEVELS="aalborg:$SHARED/levels/torcs/aalborg/aalborg.acc polynesia:$SHARED/levels/0ad/polynesia.glb"
for lv in $LEVELS; do
    n=${lv%%:*}; f=${lv#*:}
    [ -f "$f" ] || { echo "skip $n: $f absent" >&2; continue; }
    for b in 0 0.1 1 10; do run "$n.beta$b" "$f" --max-regions 128 --beta "$b"; done
    run "$n.beta1.face3" "$f" --max-regions 128 --beta 1 --boundary-points 3
    for r in 32 512; do run "$n.regions$r" "$f" --max-regions "$r"; done
done

python3 - "$OUT" <<'PY'
import json, os, sys
out = sys.argv[1]
def load(n):
    p = os.path.join(out, n + ".json")
    return json.load(open(p)) if os.path.exists(p) else None
levels = [l for l in ("aalborg", "polynesia") if load(l + ".beta1")]

print("| level | regions (edges) | models, absorbed | grid points | inside | behind a wall | back faces | valid | rays | valid s | trace s |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for l in levels:
    d = load(l + ".beta1"); c = d["counts"]; s = d["seconds"]
    print(f"| {l} | {c['regions']} ({c['edges']}) | {c['models']}, {c['regions_absorbed']} | {c['grid_points']} | {c['points_inside']} | {c['points_hidden']} | {c['points_backface']} | {c['points_valid']} | {c['rays']/1e6:.1f} M | {s['valid']:.2f} | {s['trace']:.2f} |")
print()
print("| level | held-back points | eq 4 | single gradient | constant | fit (fitted points) | regularised |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for l in levels:
    d = load(l + ".beta1"); h = d["holdout_rms"]; f = d["fit_rms"]
    print(f"| {l} | {h['points']} | {h['eq4']:.4f} | {h['gradient']:.4f} | {h['constant']:.4f} | {f['eq4']:.4f} | {f['eq4_regularised']:.4f} |")
print()
print("| level | path points x 2 normals | linear SH | quadratic SH | quadratic, unregularised | bias (quadratic) | the point's own SH (no eq 4) |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for l in levels:
    p = load(l + ".beta1")["paths"]
    print(f"| {l} | {p['points']} x 2 | {p['rms_linear_quadratic'][0]:.4f} | {p['rms_linear_quadratic'][1]:.4f} | {p['rms_quadratic_unregularised']:.4f} | {p['bias_linear_quadratic'][1]:+.4f} | {p['rms_point_sh']:.4f} |")
print()
print("| level | beta | compared at | jump at b_ij mean / max | E after / before | fit RMS | crossings | crossing mean / max | + blending (tau 4 steps) | other steps mean |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for l in levels:
    d0 = load(l + ".beta0"); p0 = d0["paths"]; j0 = d0["boundary_jump"]
    print(f"| {l} | none | | {j0['mean'][0]:.4f} / {j0['max'][0]:.3f} | 1 | {d0['fit_rms']['eq4']:.4f} | {p0['crossings']} | {p0['unregularised']['crossing_mean']:.4f} / {p0['unregularised']['crossing_max']:.3f} | {p0['regularised_blended']['crossing_mean']:.4f} / {p0['regularised_blended']['crossing_max']:.3f} | {p0['unregularised']['step_mean']:.4f} |")
    for b, tag, where in (("0.1", "beta0.1", "b_ij"), ("1", "beta1", "b_ij"), ("10", "beta10", "b_ij"), ("1", "beta1.face3", "3x3 over the face")):
        d = load(l + "." + tag)
        if not d: continue
        p = d["paths"]; j = d["boundary_jump"]
        print(f"| {l} | {b} | {where} | {j['mean'][1]:.4f} / {j['max'][1]:.3f} | {j['energy'][1]/j['energy'][0]:.3f} | {d['fit_rms']['eq4_regularised']:.4f} | {p['crossings']} | {p['regularised']['crossing_mean']:.4f} / {p['regularised']['crossing_max']:.3f} | {p['regularised_blended']['crossing_mean']:.4f} / {p['regularised_blended']['crossing_max']:.3f} | {p['regularised']['step_mean']:.4f} |")
print()
print("| level | max regions | regions, models | valid points | held-back eq 4 / gradient / constant | path RMS (quadratic) | trace s |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for l in levels:
    for r, tag in ((32, "regions32"), (128, "beta1"), (512, "regions512")):
        d = load(l + "." + tag)
        if not d: continue
        c = d["counts"]; h = d["holdout_rms"]
        print(f"| {l} | {r} | {c['regions']}, {c['models']} | {c['points_valid']} | {h['eq4']:.4f} / {h['gradient']:.4f} / {h['constant']:.4f} | {d['paths']['rms_linear_quadratic'][1]:.4f} | {d['seconds']['trace']:.2f} |")
PY
