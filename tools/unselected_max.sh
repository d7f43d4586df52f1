#!/bin/sh
# The largest |AO - 1| over the pixels a receivers selector leaves out
# (README: Object masks: a pixel of weight 0 stays exactly 1), computed
# with oiiotool (Debian openimageio-tools) from the frame's own channels,
# not through obscura's mask code:
#
#   tools/unselected_max.sh OBSCURA FRAME.exr AO.exr id CHANNEL N
#       the pixels whose integer ID channel CHANNEL is not N
#   tools/unselected_max.sh OBSCURA FRAME.exr AO.exr name LAYER NAME
#       the pixels none of whose Cryptomatte ranks (LAYER00..02, ID
#       channels .r/.b as Blender writes them) holds NAME's ID, read from
#       the manifest by obscura inspect
#
# Each pixel's |AO - 1| is multiplied by a weight that is 0 on the selected
# pixels and positive on the others (by ID: min(|ID - N|, 1); by name: the
# smallest over the ranks of min(|ID_k - T| * 1e30, 1), positive wherever
# no rank holds T, as distinct floats differ); prints the maximum, 0 when
# every unselected pixel is exactly 1.
set -eu
O=$1 F=$2 A=$3 kind=$4
case "$kind" in
id)
    oiiotool "$F" --ch "$5" --chnames x --subc "$6" --abs --clamp:min=0:max=1 \
        "$A" --ch AO.Y --chnames x --absdiffc 1 --mul --printstats ;;
name)
    hex=$("$O" inspect "$F" 2>/dev/null | awk -v n="$6" '$2 == n { print $1; exit }')
    [ -n "$hex" ] || { echo "unselected_max.sh: no Cryptomatte name '$6' in $F" >&2; exit 1; }
    t=$(python3 -c "import struct, sys; print(repr(struct.unpack('>f', bytes.fromhex(sys.argv[1]))[0]))" "$hex")
    ranks=""
    for k in 00 01 02; do for c in r b; do
        ranks="$ranks $F --ch $5$k.$c --chnames x --absdiffc $t --mulc 1e30 --clamp:max=1"
    done; done
    # shellcheck disable=SC2086
    oiiotool $ranks --min --min --min --min --min "$A" --ch AO.Y --chnames x --absdiffc 1 --mul \
        --printstats ;;
*) echo "unselected_max.sh: id or name, not '$kind'" >&2; exit 2 ;;
esac | sed -n 's/.*Stats Max: *\([^ ]*\).*/\1/p'
