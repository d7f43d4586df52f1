#!/bin/sh
# The baked vertices against a per-pixel reference (bench/BAKE.md, "Against
# a per-pixel reference"; make bake-quality).  For each level: bake it
# four times from the same samples and rays (the least-squares fit with
# the paper's alpha 1 and with alpha 0, and the two baselines, --values
# fit|face_mean|point), make cameras over it from
# its vertices (tools/level_cameras.py), and at each camera compare the
# G-buffer's interpolated _AO, _AO_SHORT, _AO_LONG (obscura gbuffer) with
# the same quantity ray traced per pixel (obscura reference --obscurance)
# by obscura compare (MSE, SSIM over the pixels with geometry).  The
# reference's own noise is measured at the first camera of each level: a
# second reference with another seed, MSE(ref, ref') / 2 = the noise's
# share of every MSE.  Prints a markdown table; files in out/bake_quality/;
# with QSTRIP (build/quality_strip) a strip per level in bench/quality/
# (rows: cameras; columns: reference, alpha 1, alpha 0, face mean, point).
# Second table, baked and screen-space AO in one frame: the reference of
# both scales (reference --near NEAR: AO_BOTH.Y = the AO within NEAR x eq 1
# at the long distance) against the alpha-1 bake's _AO_LONG alone, the
# chain's AO at --radius NEAR alone, and the two combined (obscura ao
# --baked _AO_LONG, product and min); its strip bench/quality/
# bake_combined_LEVEL.png (columns: AO_BOTH.Y, baked, screen-space,
# product, min).
#
#   bench/bake_quality.sh        (OBSCURA: the CLI; OBSCURA_SHARED_DATA)
# Sizes (environment): LEVELS (default "aalborg polynesia"; also forza,
# tiber), RAYS (bake rays per sample, 64), SPF (bake samples per face, 4),
# SPP (reference rays per pixel, 64), CAMS (cameras per level, 3), WIDTH
# and HEIGHT (256 x 192), DISTANCES (2,300), BLEND (0.03), NEAR (2: the
# screen-space AO's distance).
set -eu
OBSCURA=${OBSCURA:-build/obscura}
DATA=${OBSCURA_SHARED_DATA:-../shared/data}/levels
LEVELS=${LEVELS:-aalborg polynesia}
RAYS=${RAYS:-64}
SPF=${SPF:-4}
SPP=${SPP:-64}
CAMS=${CAMS:-3}
WIDTH=${WIDTH:-256}
HEIGHT=${HEIGHT:-192}
DISTANCES=${DISTANCES:-2,300}
BLEND=${BLEND:-0.03}
NEAR=${NEAR:-2}
QSTRIP=${QSTRIP:-}
VARIANTS="fit fit_alpha0 face_mean point"
if [ ! -d "$DATA" ]; then
    echo "bake quality: $DATA is absent (the shared levels): nothing measured"
    exit 0
fi
O=out/bake_quality
mkdir -p "$O"
rows="$O/rows.txt"
both="$O/both.txt"
: >"$rows"
: >"$both"

path_of() {
    case $1 in
    aalborg) echo torcs/aalborg/aalborg.acc ;;
    forza) echo torcs/forza/forza.acc ;;
    polynesia) echo 0ad/polynesia.glb ;;
    tiber) echo 0ad/battle_for_the_tiber.glb ;;
    *) echo "bake quality: unknown level '$1' (aalborg, forza, polynesia, tiber)" >&2; exit 2 ;;
    esac
}

# compare REF G CH_REF CH_G: "mse ssim"
metrics() {
    "$OBSCURA" compare "$1" "$2" --channel-a "$3" --channel-b "$4" --json |
        python3 -c "import json,sys; d=json.loads(sys.stdin.read()); print(d['mse'], d['ssim'], d['pixels'])"
}

echo "bake quality: levels '$LEVELS', bake $RAYS rays x $SPF samples/face, reference $SPP rays/pixel," \
     "$CAMS cameras at ${WIDTH}x$HEIGHT, distances $DISTANCES, blend $BLEND" >&2
for name in $LEVELS; do
    level="$DATA/$(path_of "$name")"
    if [ ! -f "$level" ]; then
        echo "bake quality: $level is absent: $name skipped" >&2
        continue
    fi
    for v in $VARIANTS; do
        case $v in
        fit_alpha0) opt="--values fit --alpha 0" ;;
        *) opt="--values $v" ;;
        esac
        echo "bake quality: $name: bake $opt" >&2
        "$OBSCURA" bake "$level" -o "$O/${name}_$v.glb" --rays "$RAYS" --samples-per-face "$SPF" \
            --distances "$DISTANCES" --blend "$BLEND" $opt --report "$O/${name}_$v.json" -q
    done
    tiles=""
    tiles2=""
    python3 tools/level_cameras.py "$O/${name}_fit.glb" "$O" "$CAMS" "$WIDTH" "$HEIGHT" >/dev/null
    i=0
    while [ "$i" -lt "$CAMS" ]; do
        cam="$O/${name}_cam$i.json"
        mv "$O/cam$i.json" "$cam"
        echo "bake quality: $name camera $i: reference" >&2
        ref="$O/${name}_ref$i.exr"
        "$OBSCURA" reference "$O/${name}_fit.glb" --camera "$cam" -o "$ref" --obscurance "$DISTANCES" \
            --blend "$BLEND" --near "$NEAR" --spp "$SPP" --seed 1 -q
        if [ "$i" -eq 0 ]; then
            "$OBSCURA" reference "$O/${name}_fit.glb" --camera "$cam" -o "$O/${name}_ref0b.exr" \
                --obscurance "$DISTANCES" --blend "$BLEND" --spp "$SPP" --seed 2 -q
            set -- $(metrics "$ref" "$O/${name}_ref0b.exr" AO.Y AO.Y) \
                   $(metrics "$ref" "$O/${name}_ref0b.exr" AO_SHORT.Y AO_SHORT.Y) \
                   $(metrics "$ref" "$O/${name}_ref0b.exr" AO_LONG.Y AO_LONG.Y)
            echo "$name noise 0 $1 $2 $4 $5 $7 $8 $3" >>"$rows"
        fi
        tiles="$tiles --grey $ref AO.Y"
        for v in $VARIANTS; do
            g="$O/${name}_${v}_g$i.exr"
            tiles="$tiles --grey $g _AO"
            "$OBSCURA" gbuffer "$O/${name}_$v.glb" --baked --camera "$cam" -o "$g" -q
            set -- $(metrics "$ref" "$g" AO.Y _AO) $(metrics "$ref" "$g" AO_SHORT.Y _AO_SHORT) \
                   $(metrics "$ref" "$g" AO_LONG.Y _AO_LONG)
            echo "$name $v $i $1 $2 $4 $5 $7 $8 $3" >>"$rows"
        done
        # baked and screen-space AO in one frame, on the alpha-1 G-buffer
        g="$O/${name}_fit_g$i.exr"
        "$OBSCURA" ao "$g" -o "$O/${name}_prod$i.exr" --radius "$NEAR" --baked _AO_LONG --float -q
        "$OBSCURA" ao "$g" -o "$O/${name}_min$i.exr" --radius "$NEAR" --baked _AO_LONG \
            --baked-combine min --float -q
        for what in baked:prod:AOBaked.Y screen:prod:AOScreen.Y product:prod:AO.Y min:min:AO.Y; do
            label=${what%%:*}; rest=${what#*:}; file=${rest%%:*}; ch=${rest#*:}
            set -- $(metrics "$ref" "$O/${name}_$file$i.exr" AO_BOTH.Y "$ch")
            echo "$name $label $i $1 $2 $3" >>"$both"
        done
        tiles2="$tiles2 --grey $ref AO_BOTH.Y --grey $O/${name}_prod$i.exr AOBaked.Y"
        tiles2="$tiles2 --grey $O/${name}_prod$i.exr AOScreen.Y --grey $O/${name}_prod$i.exr AO.Y"
        tiles2="$tiles2 --grey $O/${name}_min$i.exr AO.Y"
        set -- $(metrics "$ref" "$O/${name}_prod$i.exr" AO_NEAR.Y AOScreen.Y)
        echo "$name screen_vs_near $i $1 $2 $3" >>"$both"
        i=$((i + 1))
    done
    if [ -n "$QSTRIP" ] && [ -x "$QSTRIP" ]; then
        mkdir -p bench/quality
        "$QSTRIP" "bench/quality/bake_$name.png" --scale 2 --cols 5 $tiles
        "$QSTRIP" "bench/quality/bake_combined_$name.png" --scale 2 --cols 5 $tiles2
        echo "bake quality: wrote bench/quality/bake_$name.png, bake_combined_$name.png" >&2
    fi
done

python3 - "$rows" "$both" "$NEAR" <<'PY'
import sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip()]
names = {"fit": "least squares (alpha 1)", "fit_alpha0": "least squares (alpha 0)",
         "face_mean": "per-face averaging",
         "point": "point sampling", "noise": "reference noise (MSE / 2, SSIM of two seeds)"}
print("| level | vertex values | cameras | pixels | _AO MSE | _AO SSIM | _AO_SHORT MSE | _AO_SHORT SSIM | _AO_LONG MSE | _AO_LONG SSIM |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
levels = []
for r in rows:
    if r[0] not in levels:
        levels.append(r[0])
for lv in levels:
    for v in ("fit", "fit_alpha0", "face_mean", "point", "noise"):
        sel = [r for r in rows if r[0] == lv and r[1] == v]
        if not sel:
            continue
        m = [sum(float(r[k]) for r in sel) / len(sel) for k in range(3, 9)]
        if v == "noise":
            m[0] /= 2; m[2] /= 2; m[4] /= 2
        px = sum(int(float(r[9])) for r in sel)
        print("| %s | %s | %d | %d | %.5f | %.4f | %.5f | %.4f | %.5f | %.4f |" % (
            lv, names[v], len(sel), px, m[0], m[1], m[2], m[3], m[4], m[5]))
print()
print("Per camera (_AO MSE): " + "; ".join(
    "%s cam %s %s %.5f" % (r[0], r[2], r[1], float(r[3])) for r in rows if r[1] != "noise"))
both = [l.split() for l in open(sys.argv[2]) if l.strip()]
near = sys.argv[3]
labels = {"baked": "baked _AO_LONG alone", "screen": "screen-space alone (--radius %s)" % near,
          "product": "product (--baked _AO_LONG)", "min": "min (--baked-combine min)",
          "screen_vs_near": "screen-space against AO_NEAR.Y (its own reference)"}
print()
print("| level | against AO_BOTH.Y (AO within %s x eq 1 at the long distance) | cameras | pixels | MSE | SSIM |" % near)
print("| --- | --- | --- | --- | --- | --- |")
for lv in levels:
    for k in ("baked", "screen", "product", "min", "screen_vs_near"):
        sel = [r for r in both if r[0] == lv and r[1] == k]
        if not sel:
            continue
        print("| %s | %s | %d | %d | %.5f | %.4f |" % (
            lv, labels[k], len(sel), sum(int(float(r[5])) for r in sel),
            sum(float(r[3]) for r in sel) / len(sel), sum(float(r[4]) for r in sel) / len(sel)))
print()
print("Per camera (MSE against AO_BOTH.Y): " + "; ".join(
    "%s cam %s %s %.5f" % (r[0], r[2], r[1], float(r[3])) for r in both if r[1] != "screen_vs_near"))
PY
