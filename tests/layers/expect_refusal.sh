#!/usr/bin/env bash
# The include-layer check must refuse a planted tree: exit 1 and every expected
# line in its report.
#   tests/layers/expect_refusal.sh TABLE TREE EXPECTED...
set -uo pipefail
table="$1" tree="$2"
shift 2
report=$("$(dirname "$0")/../../scripts/check-layers.sh" --table "$table" "$tree")
status=$?
echo "$report"
if [[ $status != 1 ]]; then
  echo "expect_refusal: check-layers exited $status on $tree, not 1" >&2
  exit 1
fi
for expected in "$@"; do
  if ! grep -qF -- "$expected" <<<"$report"; then
    echo "expect_refusal: the report lacks: $expected" >&2
    exit 1
  fi
done
