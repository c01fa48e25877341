#!/usr/bin/env bash
# A program's --help, checked (CTest help_* tests, demos/CMakeLists.txt):
#   check_help.sh <program> <a manual page> <regex>...
# --help must return 0, match every extended regex (its kinds, defaults and an example), and name where the manual is
# ("... is in DIR" on one line): DIR must hold the page named.
set -euo pipefail
program=$1 page=$2
shift 2
out=$("$program" --help 2>&1) || { echo "$program --help failed: $out" >&2; exit 1; }
for regex in "$@"; do
  grep -Eq -- "$regex" <<<"$out" || { echo "$program --help lacks /$regex/:"; echo "$out"; exit 1; } >&2
done
dir=$(grep -Eo 'is in /[^ ]+' <<<"$out" | head -n1 | cut -c7-)
[ -n "$dir" ] || { echo "$program --help names no manual directory (\"is in DIR\")" >&2; exit 1; }
[ -f "$dir/$page" ] || { echo "$program --help names $dir, which has no $page" >&2; exit 1; }
echo "$program --help: $# patterns, the manual in $dir"
