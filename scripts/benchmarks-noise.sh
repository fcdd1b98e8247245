#!/usr/bin/env bash
# Less noise per second (issue 24): for each scene, a 4096-spp reference of the renderer itself,
# then renders of 16 ... 1024 spp, each one's render time and RMSE (of the displayed, tone-mapped values) against the
# reference; from them the error's slope between 16 and 256 spp and the time to RMSE 0.02, 0.01,
# 0.005 and 0.0025 (interpolated in log-log between the renders that bracket it; "-" when even
# 1024 spp does not reach it). 512x512, 2 threads, path. About 12 minutes per Cornell scene and
# 35 for the sky-lit Sponza on this machine.
#   scripts/benchmarks-noise.sh [SCENE ...]    scenes: cornell-original cornell-water sponza-sky
#   TRACER=path/to/tracer scripts/benchmarks-noise.sh ...   another build (an older commit's)
#   SIZE=256 scripts/benchmarks-noise.sh ...   a smaller image (a quarter of the time; RMSE per pixel
#                                              barely moves with the size)
#   ADAPTIVE=1 scripts/benchmarks-noise.sh ... also adaptive sampling: the same table for
#                                              --noise-threshold 0.04 ... 0.0025 (--spp 4096 at most)
# Writes docs/bench/noise-SCENE.md (or noise-SCENE-SIZE.md for another SIZE, -LABEL with LABEL=...).
# Fixed spp is --noise-threshold 0 (every pixel every sample); older builds without the flag:
# FIXED_FLAGS= (empty).
source "$(dirname "$0")/bench-prelude.sh"
size=${SIZE:-512}
label=${LABEL:+-$LABEL}
[[ $size == 512 ]] || label="-$size$label"
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell-original cornell-water sponza-sky)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for scene in "${scenes[@]}"; do
  line=$(path_scene_flags "$scene")
  read -r -a flags <<<"$line"
  common=("${flags[@]}" --integrator path --width "$size" --height "$size" --threads 2 -q)
  fixed=(${FIXED_FLAGS---noise-threshold 0})
  $T render "${common[@]}" "${fixed[@]}" --spp 4096 --seed 99 -o "$work/ref.png"
  # One row: the render's time, samples taken and RMSE against the reference.
  row() {
    $T render "${common[@]}" "$@" -o "$work/img.png" --stats-json "$work/s.json"
    echo "$(field "$work/s.json" render_ms) $(field "$work/s.json" primary)" \
      "$($T compare "$work/ref.png" "$work/img.png" | sed -E 's/.*RMSE ([^,]*),.*/\1/')"
  }
  rows=()
  for spp in 16 32 64 128 256 512 1024; do rows+=("$spp $(row "${fixed[@]}" --spp $spp)"); done
  if [[ -n ${ADAPTIVE:-} ]]; then
    adaptive=()
    for t in 0.04 0.02 0.01 0.005 0.0025; do adaptive+=("$t $(row --noise-threshold $t --spp 4096)"); done
  fi
  {
    printf '%s\n' "${rows[@]}" | awk -v scene="$scene" -v size="$size" -v tracer="$($T --version 2>/dev/null | head -1)" '
      { spp[NR] = $1; s[NR] = $2 / 1000; taken[NR] = $3; e[NR] = $4; n = NR }
      END {
        printf "%s, %dx%d, path, 2 threads (%s); RMSE of the displayed values (tone-mapped, 8-bit, in [0, 1]) against 4096 spp (seed 99)\n\n", scene, size, size, tracer
        print "| spp | render s | Msamples/s | RMSE |"
        print "|---:|---:|---:|---:|"
        for (i = 1; i <= n; ++i) printf "| %d | %.2f | %.3f | %.5f |\n", spp[i], s[i], taken[i] / s[i] / 1e6, e[i]
        for (i = 1; i <= n; ++i) { if (spp[i] == 16) a = i; if (spp[i] == 256) b = i }
        printf "\nslope of RMSE against spp, 16 to 256: N^%.3f\n\n", log(e[b] / e[a]) / log(spp[b] / spp[a])
      }'
    if [[ -n ${ADAPTIVE:-} ]]; then
      echo "Adaptive sampling, --spp 4096 at most:"
      echo
      echo "| --noise-threshold | render s | samples per pixel | RMSE |"
      echo "|---:|---:|---:|---:|"
      for r in "${adaptive[@]}"; do
        read -r t ms taken e <<<"$r"
        awk -v t="$t" -v ms="$ms" -v taken="$taken" -v e="$e" -v px="$((size * size))" \
          'BEGIN { printf "| %s | %.2f | %.1f | %.5f |\n", t, ms / 1000, taken / px, e }'
      done
      echo
    fi
    # Seconds to each RMSE (the rows' times are milliseconds).
    to_rmse() { awk '{ $2 = $2 / 1000; print }' | seconds_to_rmse 0.02 0.01 0.005 0.0025; }
    read -r -a by_spp <<<"$(printf '%s\n' "${rows[@]}" | to_rmse)"
    by_threshold=(- - - -)
    [[ -n ${ADAPTIVE:-} ]] && read -r -a by_threshold <<<"$(printf '%s\n' "${adaptive[@]}" | to_rmse)"
    echo "| RMSE | seconds to reach it: fixed spp | adaptive |"
    echo "|---:|---:|---:|"
    targets=(0.02 0.01 0.005 0.0025)
    for i in 0 1 2 3; do echo "| ${targets[$i]} | ${by_spp[$i]} | ${by_threshold[$i]} |"; done
  } | tee "$O/noise-$scene$label.md"
done
