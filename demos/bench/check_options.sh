#!/usr/bin/env bash
# quathinge-bench's --scenes/--kinds (CTest bench_scenes_kinds): the spellings quathinge-compare takes select exactly
# the cases they name.   check_options.sh <quathinge-bench>
set -euo pipefail
bench=$1
fail() { echo "bench_scenes_kinds: $*" >&2; exit 1; }
for spelling in "-s chain10 joint -k stock quaternion+stab" "--scenes=chain10,joint --kinds stock,quaternion+stab"; do
  # shellcheck disable=SC2086  # the spelling is meant to split
  out=$("$bench" $spelling --benchmark_list_tests=true) || fail "$spelling: failed"
  [ "$(grep -c . <<<"$out")" -gt 2 ] || fail "$spelling: listed $(grep -c . <<<"$out") cases"
  other=$(grep -v -E '^(step/chain10|joint/[^ ]*)/(stock|quaternion\+stab)(/iterations:[0-9]+)?$' <<<"$out" || true)
  [ -z "$other" ] || fail "$spelling: listed cases it does not name: $other"
  grep -qE '^step/chain10/quaternion\+stab(/iterations:[0-9]+)?$' <<<"$out" || fail "$spelling: no step/chain10/quaternion+stab"
  grep -qx 'joint/a0.5/free/stock' <<<"$out" || fail "$spelling: no joint/a0.5/free/stock"
done
! "$bench" --kinds no_such_kind --benchmark_list_tests=true 2>/dev/null || fail "an unknown kind was accepted"
echo "bench_scenes_kinds: both spellings select chain10's and the joint cases, stock and quaternion+stab only"
