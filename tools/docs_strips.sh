#!/bin/sh
# README's pictures of the compositor's outputs (docs/*_strip.png), from
# the bundled room_small frame and the deep fixture, through obscura and
# oiiotool (Debian openimageio-tools).  Run from the repository root after
# make:  sh tools/docs_strips.sh [build/obscura]
#
#   docs/aovs_strip.png         albedo | AO.Y | AOMultiBounce | Samples.Y / 32
#   docs/multibounce_strip.png  albedo x AO | albedo x multi-bounce AO
#   docs/bent_strip.png         normals | vaopp's bent normal | gtao's (0.5 + 0.5 n)
#   docs/deep_strip.png         deep fixture, 6x: front node's AO | flat AO |
#                               oiiotool's flatten of the deep AO (+ 1 - A)
set -eu
OBSCURA=${1:-build/obscura}
R=tests/data/room_small.exr
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
srgb() { oiiotool "$1" --colorconvert linear sRGB -d uint8 -o "$2"; }

"$OBSCURA" ao "$R" --output aovs --color albedo --multibounce on -o "$T/aovs.exr" -q
oiiotool "$R" --ch R=ViewLayer.DiffCol.R,G=ViewLayer.DiffCol.G,B=ViewLayer.DiffCol.B -o "$T/alb.exr"
oiiotool "$T/aovs.exr" --ch AO.Y,AO.Y,AO.Y --chnames R,G,B -o "$T/ao.exr"
oiiotool "$T/aovs.exr" --ch AOMultiBounce.R,AOMultiBounce.G,AOMultiBounce.B --chnames R,G,B -o "$T/mb.exr"
oiiotool "$T/aovs.exr" --ch Samples.Y,Samples.Y,Samples.Y --chnames R,G,B --mulc 0.03125 -o "$T/n.exr"
for f in alb ao mb; do srgb "$T/$f.exr" "$T/$f.png"; done
oiiotool "$T/n.exr" -d uint8 -o "$T/n.png" # a count, linear
oiiotool "$T/alb.png" "$T/ao.png" "$T/mb.png" "$T/n.png" --mosaic:pad=4 4x1 -o docs/aovs_strip.png

oiiotool "$T/alb.exr" "$T/ao.exr" --mul -o "$T/c1.exr"
oiiotool "$T/alb.exr" "$T/mb.exr" --mul -o "$T/c2.exr"
srgb "$T/c1.exr" "$T/c1.png"
srgb "$T/c2.exr" "$T/c2.png"
oiiotool "$T/c1.png" "$T/c2.png" --mosaic:pad=4 2x1 -o docs/multibounce_strip.png

oiiotool "$R" --ch R=ViewLayer.Normal.X,G=ViewLayer.Normal.Y,B=ViewLayer.Normal.Z --mulc 0.5 --addc 0.5 -d uint8 -o "$T/nrm.png"
for m in vaopp gtao; do
    "$OBSCURA" ao "$R" --method "$m" --output bent -o "$T/bent_$m.png" -q
done
oiiotool "$T/nrm.png" "$T/bent_vaopp.png" "$T/bent_gtao.png" --mosaic:pad=4 3x1 -o docs/bent_strip.png

"$OBSCURA" ao tests/data/deep_small.exr --output deep --blur off --radius 2 --backend cpu -o "$T/deep.exr" -q
oiiotool "$T/deep.exr" --subimage 1 --ch AOFront.Y,AOFront.Y,AOFront.Y --chnames R,G,B -o "$T/front.exr"
oiiotool "$T/deep.exr" --subimage 1 --ch AO.Y,AO.Y,AO.Y --chnames R,G,B -o "$T/flat.exr"
oiiotool "$T/deep.exr" --flatten --ch AO.Y -o "$T/fa.exr"
oiiotool "$T/deep.exr" --flatten --ch A -o "$T/fb.exr"
oiiotool "$T/fa.exr" "$T/fb.exr" --sub --addc 1 --ch 0,0,0 --chnames R,G,B -o "$T/fl.exr"
for f in front flat fl; do
    oiiotool "$T/$f.exr" --resize:filter=box 288x192 --colorconvert linear sRGB -d uint8 -o "$T/$f.png"
done
oiiotool "$T/front.png" "$T/flat.png" "$T/fl.png" --mosaic:pad=4 3x1 -o docs/deep_strip.png
echo "wrote docs/aovs_strip.png docs/multibounce_strip.png docs/bent_strip.png docs/deep_strip.png"
