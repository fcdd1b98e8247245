# Sourced first by every scripts/benchmarks*.sh: from the project root, the release preset built,
# T the tracer binary, O the folder of results, and field FILE KEY reading one number from a
# --stats-json file (pretty-printed: one key per line).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[1]}")/.."
# TRACER=path/to/tracer measures another build (an older commit's) and builds nothing.
if [[ -z ${TRACER:-} ]]; then
  cmake --preset release >/dev/null
  cmake --build --preset release >/dev/null
fi
T=${TRACER:-build/release/tracer}
O=docs/bench
mkdir -p "$O"
field() { sed -n "s/^ *\"$2\": \([-0-9.e+]*\),\{0,1\}$/\1/p" "$1" | head -1; }
