#!/bin/sh
# Writes the generated blocks of README.md:
#   params:begin .. params:end     `obscura params --markdown` (the parameter table)
#   obscurad:begin .. obscurad:end `obscurad --help` (the daemon's option table)
#   bake-params:begin .. bake-params:end  `obscura bake --params-markdown`
#   dyn-params:begin .. dyn-params:end    `obscura bake-dynamic --params-markdown`
#   tools/readme_params.sh [--check] OBSCURA OBSCURAD [README]     (make readme)
# With --check, exits 1 when README.md is out of date instead.
set -eu
check=0
[ "${1:-}" = "--check" ] && { check=1; shift; }
OBSCURA=${1:-build/obscura}
OBSCURAD=${2:-build/obscurad}
README=${3:-README.md}
tmp=$(mktemp)
trap 'rm -f "$tmp" "$tmp.d" "$tmp.b" "$tmp.y" "$tmp.new"' EXIT
"$OBSCURA" params --markdown > "$tmp"
"$OBSCURA" bake --params-markdown > "$tmp.b"
"$OBSCURA" bake-dynamic --params-markdown > "$tmp.y"
{ echo '```'; "$OBSCURAD" --help | sed -n '/^options:/,$p'; echo '```'; } > "$tmp.d"
awk -v table="$tmp" -v daemon="$tmp.d" -v bake="$tmp.b" -v dyn="$tmp.y" '
    /<!-- params:begin -->/ { print; while ((getline l < table) > 0) print l; skip = 1; next }
    /<!-- obscurad:begin -->/ { print; while ((getline l < daemon) > 0) print l; skip = 1; next }
    /<!-- bake-params:begin -->/ { print; while ((getline l < bake) > 0) print l; skip = 1; next }
    /<!-- dyn-params:begin -->/ { print; while ((getline l < dyn) > 0) print l; skip = 1; next }
    /<!-- (params|obscurad|bake-params|dyn-params):end -->/ { skip = 0 }
    !skip { print }' "$README" > "$tmp.new"
if [ "$check" -eq 1 ]; then
    if cmp -s "$README" "$tmp.new"; then exit 0; fi
    echo "README.md's generated tables are out of date: run 'make readme'" >&2
    diff "$README" "$tmp.new" >&2 || true
    exit 1
fi
mv "$tmp.new" "$README"
