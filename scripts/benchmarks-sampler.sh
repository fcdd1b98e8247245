#!/usr/bin/env bash
# What the stratified sampler costs (issue 40): path-traced samples per second of tracer's
# Sobol-Burley samples against the same renderer drawing independent samples (the `independent`
# preset: one hash per dimension, nothing stratified), on the three scenes of the noise benchmark.
# The two builds alternate, ROUNDS times per scene; the machine's speed drifts by 10-30 % between
# runs, so the table gives each build's best and median and the ratio of the medians of the
# per-round ratios. About 5 minutes on 2 cores.
#   scripts/benchmarks-sampler.sh [SCENE ...]   scenes: cornell-original cornell-water sponza-sky
#   ROUNDS=11 SIZE=256 SPP=16 THREADS=2         the defaults
# Writes docs/bench/sampler.md.
source "$(dirname "$0")/bench-prelude.sh"
cmake --preset independent >/dev/null
cmake --build --preset independent >/dev/null
I=build/independent/tracer
rounds=${ROUNDS:-11} size=${SIZE:-256} spp=${SPP:-16} threads=${THREADS:-2}
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell-original cornell-water sponza-sky)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# samples_per_s TRACER FLAGS...: Msamples/s of one render
samples_per_s() {
  local t=$1
  shift
  "$t" render "$@" --integrator path --spp "$spp" --width "$size" --height "$size" --threads "$threads" \
    --noise-threshold 0 -q -o "$work/img.png" --stats-json "$work/s.json"
  awk -v s="$(field "$work/s.json" samples_per_s)" 'BEGIN { printf "%.4f", s / 1e6 }'
}
{
  echo "Path-traced Msamples/s, ${size}x${size}, $spp spp, $threads threads, $rounds alternating rounds ($($T --version | head -1))"
  echo
  echo "| scene | Sobol-Burley: best | median | independent: best | median | Sobol-Burley / independent (median of rounds) |"
  echo "|---|---:|---:|---:|---:|---:|"
  for scene in "${scenes[@]}"; do
    line=$(path_scene_flags "$scene")
    read -r -a flags <<<"$line"
    rows=()
    for _ in $(seq "$rounds"); do
      rows+=("$(samples_per_s "$T" "${flags[@]}") $(samples_per_s "$I" "${flags[@]}")")
    done
    printf '%s\n' "${rows[@]}" | awk -v scene="$scene" '
      function median(v, n,   i, j, t) {
        for (i = 2; i <= n; ++i) for (j = i; j > 1 && v[j - 1] > v[j]; --j) { t = v[j]; v[j] = v[j - 1]; v[j - 1] = t }
        return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
      }
      { a[NR] = $1; b[NR] = $2; r[NR] = $1 / $2; if ($1 > ba) ba = $1; if ($2 > bb) bb = $2; n = NR }
      END { printf "| %s | %.3f | %.3f | %.3f | %.3f | %.3f |\n", scene, ba, median(a, n), bb, median(b, n), median(r, n) }'
  done
} | tee "$O/sampler.md"
