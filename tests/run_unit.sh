#!/bin/sh
# Runs each cmocka unit-test binary given on the command line; fails when
# any fails.  Tests run from the repository root with a private temp dir.
set -u
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OBSCURA_TEST_TMP="$tmp"
fail=0
for t in "$@"; do
    if ! "$t"; then
        echo "FAILED: $t" >&2
        fail=1
    fi
done
exit $fail
