#!/usr/bin/env bash
# Formats every C++ file git tracks with the repository's .clang-format (Google style, 120 columns).
#   scripts/format.sh           rewrite in place
#   scripts/format.sh --check   change nothing; list the files that differ and fail (CI)
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.cpp' '*.hpp' '*.h')
if [[ "${1:-}" == "--check" ]]; then
  clang-format --dry-run --Werror "${files[@]}"
  echo "format: ${#files[@]} files follow .clang-format"
else
  clang-format -i "${files[@]}"
fi
