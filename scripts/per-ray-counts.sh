#!/usr/bin/env bash
# Instructions and data-cache read misses per ray of one `tracer render` command, counted by
# cachegrind (exact and repeatable, unlike times on a shared machine). The command runs twice,
# at two image sizes; the difference of the counts over the difference of the rays is the cost
# of one ray, loading and building cancelled out. The caches simulated are this machine's: L1D
# 48 KiB 12-way and a 1 MiB 16-way last level (its L2). Valgrind has no AVX-512: Highway's
# kernels run their AVX2 target under it.
#   scripts/per-ray-counts.sh [--sizes 128,256] [--top N] -- build/release/tracer render SCENE [flags...]
# Flags must not include --width, --height, -o or --stats-json; add --threads 1. --top N also
# lists the N functions that cost most per ray (cg_diff of the two runs).
set -euo pipefail
sizes=128,256
top=0
while [[ ${1:-} == --sizes || ${1:-} == --top ]]; do
  case $1 in
    --sizes) sizes=$2 ;;
    --top) top=$2 ;;
  esac
  shift 2
done
[[ ${1:-} == -- ]] && shift
if (($# < 2)); then
  sed -n '2,10p' "$0" >&2
  exit 2
fi
command -v valgrind >/dev/null || { echo "per-ray-counts: needs valgrind (apt-get install valgrind)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Debian 12's libhwy.so.1 measures its timer with RDTSCP in a static initializer, an instruction
# valgrind 3.19 does not know (SIGILL before main). A one-function library preloaded in its place
# answers that call; nothing the render runs uses the timer.
cat > "$work/shim.cc" <<'SHIM'
#include <cstdint>
namespace hwy::platform {
uint64_t TimerResolution() { return 1; }
}  // namespace hwy::platform
SHIM
c++ -shared -fPIC -O2 -o "$work/libhwy-timer-shim.so" "$work/shim.cc"

# One run: prints "Ir D1mr DLmr rays".
count() {
  local size=$1
  shift
  LD_PRELOAD="$work/libhwy-timer-shim.so" valgrind --tool=cachegrind --cache-sim=yes --I1=32768,8,64 --D1=49152,12,64 --LL=1048576,16,64 \
    --cachegrind-out-file="$work/cg-$size" "$@" --width "$size" --height "$size" -q \
    --stats-json "$work/s-$size.json" -o "$work/img-$size.ppm" > "$work/log-$size" 2>&1 ||
    { tail -n 20 "$work/log-$size" >&2; echo "per-ray-counts: the command failed under valgrind" >&2; exit 1; }
  local rays
  rays=$(grep -A8 '"rays": {' "$work/s-$size.json" | grep -m1 -o '"total": [0-9]*' | awk '{print $2}')
  awk -v rays="$rays" '
    /^events:/ { for (i = 2; i <= NF; ++i) col[$i] = i - 1 }
    /^summary:/ { print $(col["Ir"] + 1), $(col["D1mr"] + 1), $(col["DLmr"] + 1), rays }' "$work/cg-$size"
}

IFS=, read -r small large <<< "$sizes"
read -r ir1 d11 dl1 r1 < <(count "$small" "$@")
read -r ir2 d12 dl2 r2 < <(count "$large" "$@")
awk -v ir1="$ir1" -v ir2="$ir2" -v d11="$d11" -v d12="$d12" -v dl1="$dl1" -v dl2="$dl2" -v r1="$r1" -v r2="$r2" \
  'BEGIN {
     rays = r2 - r1
     printf "rays: %d more at the larger size\n", rays
     printf "per ray: %.0f instructions, %.2f L1D read misses, %.3f last-level read misses\n",
            (ir2 - ir1) / rays, (d12 - d11) / rays, (dl2 - dl1) / rays
   }'

if ((top > 0)); then
  # Per function: the larger run's counts minus the smaller's, over the extra rays.
  rays=$((r2 - r1))
  cg_diff "$work/cg-$small" "$work/cg-$large" > "$work/cg-diff" 2>/dev/null
  echo "functions, per ray (instructions, L1D read misses, last-level read misses):"
  cg_annotate --show=Ir,D1mr,DLmr --sort=D1mr --threshold=0 --auto=no "$work/cg-diff" 2>/dev/null |
    awk -v rays="$rays" -v top="$top" '
      /^-+$/ { dashes++; next }
      { gsub(/\( *-?[0-9.]+%\)/, ""); $0 = $0 }  # drop the percentages cg_annotate adds
      dashes >= 4 && NF >= 4 && $1 ~ /^-?[0-9,]+$/ && shown < top {
        ir = $1; d1 = $2; dl = $3; gsub(",", "", ir); gsub(",", "", d1); gsub(",", "", dl)
        name = ""; for (i = 4; i <= NF; ++i) name = name " " $i
        if (length(name) > 90) name = substr(name, 1, 90) "..."
        printf "%8.1f %7.3f %7.4f %s\n", ir / rays, d1 / rays, dl / rays, name; shown++
      }'
fi
