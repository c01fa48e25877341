#!/usr/bin/env bash
# Checks that the C++ sources follow .clang-format, with Debian 12's clang-format 14 (pinned: another version formats
# differently, so the check would move under the code). Lists every file that differs and how many lines would change.
#   bash cmake/check-format.sh          check every tracked *.cpp / *.h; exit 1 if one differs
#   bash cmake/check-format.sh --fix    reformat them in place (the same version)
#   bash cmake/check-format.sh FILE...  only these files
set -euo pipefail
cd "$(dirname "$0")/.."
fix=0
if [ "${1:-}" = --fix ]; then fix=1; shift; fi
tool=clang-format-14
command -v "$tool" >/dev/null || { echo "check-format: $tool not found (apt-get install clang-format-14)" >&2; exit 2; }
"$tool" --version | grep -q 'version 14\.' || { echo "check-format: $tool is not version 14" >&2; exit 2; }
if [ $# -gt 0 ]; then files=("$@"); else mapfile -t files < <(git ls-files '*.cpp' '*.h'); fi
changed=0 lines=0
for f in "${files[@]}"; do
  if [ "$fix" = 1 ]; then "$tool" --style=file -i "$f"; continue; fi
  n=$("$tool" --style=file "$f" | diff "$f" - | grep -c '^[<>]' || true)
  if [ "$n" -gt 0 ]; then
    echo "check-format: $f: $n lines differ"
    changed=$((changed + 1)) lines=$((lines + n))
  fi
done
[ "$fix" = 1 ] && { echo "check-format: reformatted ${#files[@]} files with $("$tool" --version)"; exit 0; }
if [ "$changed" -gt 0 ]; then
  echo "check-format: $changed of ${#files[@]} files differ from .clang-format ($lines diff lines; fix: bash cmake/check-format.sh --fix)"
  exit 1
fi
echo "check-format: ${#files[@]} files follow .clang-format ($("$tool" --version | sed 's/.*version /clang-format /'))"
