#!/usr/bin/env bash
# The folders of src/ are layers (docs/ARCHITECTURE.md): a file may include its own folder or a
# lower layer, never a higher one or a sibling of its own layer. accel/'s sub-folders are layers
# within it, and the files directly in accel/ (the factory) the top of them. Fails, listing every
# include that points up or sideways.
set -euo pipefail
cd "$(dirname "$0")/.."

# folder:layer, lowest first; accel's sub-layers (kernels, bvh, wide_bvh, builders, then accel/
# two_level, then accel/ itself) within its layer 3.
layers="base:0 math:1 scene:2 parallel:2 importers:3 film:3 accel:3 io:4 shade:4 denoise:4 render:5 frontend:6 view:7 mpi:7 cli:8"
sublayers="accel/kernels:0 accel/bvh:1 accel/wide_bvh:2 accel/builders:3 accel/two_level:4 accel:5"
declare -A rank
for entry in $layers; do rank[${entry%%:*}]=$((${entry##*:} * 10)); done
for entry in $sublayers; do rank[${entry%%:*}]=$((rank[accel] + ${entry##*:})); done
# The layer a path under src/ (or an include, relative to src/) belongs to.
layer_of() {
  local top=${1%%/*} rest=${1#*/}
  if [[ $top == accel && $rest == */* ]]; then echo "accel/${rest%%/*}"; else echo "$top"; fi
}

bad=0
checked=0
while IFS= read -r file; do
  folder=$(layer_of "${file#src/}")
  if [[ -z ${rank[$folder]+x} ]]; then
    echo "layers: $file: folder '$folder' has no layer (add it to scripts/check-layers.sh)" >&2
    bad=$((bad + 1))
    continue
  fi
  while IFS=: read -r line target; do
    to=$(layer_of "$target")
    checked=$((checked + 1))
    [[ $to == "$folder" ]] && continue
    if [[ -z ${rank[$to]+x} ]] || ((rank[$to] >= rank[$folder])); then
      echo "layers: $file:$line includes \"$target\": $to is not below $folder" >&2
      bad=$((bad + 1))
    fi
  done < <(grep -n '^#include "' "$file" | sed -E 's/^([0-9]+):#include "([^"]+)".*/\1:\2/')
done < <(git ls-files --cached --others --exclude-standard 'src/*')

if ((bad > 0)); then
  echo "layers: $bad include(s) point up or sideways" >&2
  exit 1
fi
echo "layers: $checked includes, every one to its own folder or a lower layer"
