#!/bin/sh
# Writes the parameter table (from `obscura params --markdown`) into
# README.md between the params:begin and params:end markers.
#   tools/readme_params.sh [OBSCURA] [README]     (make readme)
# With --check, exits 1 when README.md is out of date instead.
set -eu
check=0
[ "${1:-}" = "--check" ] && { check=1; shift; }
OBSCURA=${1:-build/obscura}
README=${2:-README.md}
tmp=$(mktemp)
trap 'rm -f "$tmp" "$tmp.new"' EXIT
"$OBSCURA" params --markdown > "$tmp"
awk -v table="$tmp" '
    /<!-- params:begin -->/ { print; while ((getline l < table) > 0) print l; skip = 1; next }
    /<!-- params:end -->/ { skip = 0 }
    !skip { print }' "$README" > "$tmp.new"
if [ "$check" -eq 1 ]; then
    if cmp -s "$README" "$tmp.new"; then exit 0; fi
    echo "README.md's parameter table is out of date: run 'make readme'" >&2
    diff "$README" "$tmp.new" >&2 || true
    exit 1
fi
mv "$tmp.new" "$README"
