#!/usr/bin/env bash
# The library's and the stabilizer's own source (plugin/) uses compiler extensions only behind the one feature macro
# (plugin/src/CompilerExtensions.h): every __attribute__, __builtin_*, vector_size, __extension__, typeof, inline asm,
# __PRETTY_FUNCTION__ or M_PI must sit in the true branch of an `#if QUATHINGE_HAVE_VECTOR_EXTENSIONS`, whose #else
# is the standard fallback. Comments are not code. Bullet's own macros are Bullet's business.
#   bash cmake/check-extensions.sh [DIR...]   (default: plugin/)
set -euo pipefail
cd "$(dirname "$0")/.."
dirs=("$@")
[ ${#dirs[@]} -gt 0 ] || dirs=(plugin)
files=$(find "${dirs[@]}" -name '*.h' -o -name '*.cpp' | sort)
# shellcheck disable=SC2086
awk '
  FNR == 1 { depth = 0 }
  {
    line = $0
    sub(/\/\/.*$/, "", line)                     # a comment (no "//" in this code'"'"'s string literals)
    if (line ~ /^[ \t]*#[ \t]*if/) {
      depth++
      kind[depth] = (line ~ /^[ \t]*#[ \t]*if[ \t]+QUATHINGE_HAVE_VECTOR_EXTENSIONS[ \t]*$/) ? "ext" : "other"
    } else if (line ~ /^[ \t]*#[ \t]*(else|elif)/) {
      if (kind[depth] == "ext") kind[depth] = "fallback"
    } else if (line ~ /^[ \t]*#[ \t]*endif/) {
      depth--
    } else if (line ~ /__attribute__|__builtin_|vector_size|__extension__|__typeof__|[^_a-zA-Z]typeof[ \t]*\(|__asm|asm[ \t]*\(|__PRETTY_FUNCTION__|M_PI/) {
      inside = 0
      for (d = 1; d <= depth; d++) if (kind[d] == "ext") inside = 1
      if (!inside) { printf "%s:%d: an extension outside #if QUATHINGE_HAVE_VECTOR_EXTENSIONS: %s\n", FILENAME, FNR, $0; bad++ }
      else allowed++
    }
  }
  END {
    if (bad) { printf "check-extensions: %d line(s) to move behind the feature macro\n", bad; exit 1 }
    printf "check-extensions: no extension outside QUATHINGE_HAVE_VECTOR_EXTENSIONS (%d behind it)\n", allowed
  }' $files
