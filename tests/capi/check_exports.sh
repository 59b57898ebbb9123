#!/usr/bin/env bash
# Freezes libmotionfield.so's exported symbols: the dynamic symbol table's
# defined symbols must be exactly the checked-in list (functions are only ever
# appended: add new ones to the list in the same change).
# Also checks the SONAME and, given the API reference, that it names every
# exported function.
#   usage: check_exports.sh LIBRARY EXPECTED_LIST [API_REFERENCE.md]
set -euo pipefail
lib=$1
expected=$2
reference=${3:-}
actual=$(nm -D --defined-only "$lib" | awk '{ print $NF }' | sed 's/@.*//' | sort -u)
if diff <(grep -v '^#' "$expected" | sed '/^$/d' | sort -u) <(echo "$actual") >/tmp/mf-exports-diff.$$; then
  echo "exported symbols: $(echo "$actual" | wc -l) as listed"
  rm -f /tmp/mf-exports-diff.$$
else
  echo "exported symbols differ from $expected ('<' listed only, '>' exported only):"
  cat /tmp/mf-exports-diff.$$
  rm -f /tmp/mf-exports-diff.$$
  exit 1
fi
# The one exception: assimp's assertion handler, replaced (prior/motion/fbx_reader.cc).
if echo "$actual" | grep -v '^mf_' | grep -v '^_ZN6Assimp17aiAssertViolationEPKcS1_i$' >/dev/null; then
  echo "symbols without the mf_ prefix are exported"
  exit 1
fi
soname=$(readelf -d "$lib" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
case "$soname" in
  libmotionfield.so.[0-9]*) echo "SONAME $soname" ;;
  *) echo "unexpected SONAME '$soname'"; exit 1 ;;
esac
if [ -n "$reference" ]; then
  missing=$(for s in $(echo "$actual" | grep '^mf_'); do grep -q "\b$s(" "$reference" || echo "$s"; done)
  if [ -n "$missing" ]; then
    echo "not described in $reference:"
    echo "$missing"
    exit 1
  fi
  echo "every exported function is described in $(basename "$reference")"
fi
