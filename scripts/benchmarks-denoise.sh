#!/usr/bin/env bash
# Time to a clean image with --denoise (issue 52): for each scene, tracer's own reference
# (REF_SPP samples, seed 99, long enough that an error of 0.005 is measurable: its own error is
# printed), then three ladders of whole-process renders, each with its wall time and RMSE of the
# display values against the reference (`tracer compare --exposure 1.5`, as
# scripts/benchmarks-cycles.sh measures Cycles):
#   - fixed spp, noisy (4, 8, ... up to MAX_SPP): the RMSE-against-spp curve without;
#   - fixed spp, --denoise (1, 2, 4, ...): the curve with, and the denoiser's share of the time;
#   - adaptive sampling with --denoise (--noise-threshold 0.08 ... 0.005, at most REF_SPP).
# Then seconds to RMSE 0.02 / 0.01 / 0.005 of each (interpolated in log-log, as benchmarks-cycles
# does). The same scenes, camera, size and threads as benchmarks-cycles.sh, whose Cycles figures
# (docs/bench/cycles-SCENE.md) these compare with.
#   scripts/benchmarks-denoise.sh [SCENE ...]     cornell-original cornell-water sponza-sky
#   SIZE=512 THREADS=2 REF_SPP=4096 MAX_SPP=256   the defaults (sponza-sky: SIZE=256)
#   PAIR_SPP=8                                    the equal-time pair's denoised spp
# Writes docs/bench/denoise-SCENE.md and an equal-time pair of PNGs, denoise-SCENE-denoised.png
# (PAIR_SPP, --denoise) and denoise-SCENE-noisy.png (without, the spp that takes as long).
# About 12 minutes for each Cornell box on 2 cores.
source "$(dirname "$0")/bench-prelude.sh"
threads=${THREADS:-2} ref_spp=${REF_SPP:-4096} max_spp=${MAX_SPP:-256}
exposure=1.5
shared=$(cd "${SHARED:-../shared}" && pwd)
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell-original cornell-water sponza-sky)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }

# The scene's flags, as benchmarks-cycles.sh renders it (Sponza without its bump maps there).
scene_flags() {
  case $1 in
    cornell-original | cornell-water) path_scene_flags "$1" ;;
    sponza-sky)
      obj=$(sponza_without_bumps "$work" "$shared")
      awk -F'\t' -v o="$obj" '$1 == "sponza" { print o, "--eye", $3, "--look", $4, "--up", $5, "--fov", $6 }' \
        "$shared/scenes/views.tsv"
      echo --env 1,1,1 ;;
    *) echo "unknown scene $1" >&2; return 2 ;;
  esac
}

# render OUT.exr FLAGS...: prints "wall_seconds denoise_seconds".
render() {
  local out=$1 start end
  shift
  start=$(now)
  $T render "${flags[@]}" --integrator path --width "$size" --height "$size" --threads "$threads" -q -o "$out" \
    --exr float --stats-json "$work/s.json" "$@"
  end=$(now)
  echo "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }') $(awk -v m="$(field "$work/s.json" denoise_ms)" 'BEGIN { print (m == "" ? 0 : m) / 1000 }')"
}
rmse() { $T compare --exposure "$exposure" "$1" "$2" | sed -E 's/.*RMSE ([^,]*),.*/\1/'; }
mean_change() { $T compare "$1" "$2" | sed -E 's/.*\(([-+0-9.]*) %\).*/\1/'; }

for name in "${scenes[@]}"; do
  size=${SIZE:-$([[ $name == sponza-sky ]] && echo 256 || echo 512)}
  read -r -a flags <<<"$(scene_flags "$name" | tr '\n' ' ')"
  read -r ref_wall _ <<<"$(render "$work/ref.exr" --spp "$ref_spp" --noise-threshold 0 --seed 99)"
  noisy=() denoised=() adaptive=()
  for ((spp = 4; spp <= max_spp; spp *= 2)); do
    read -r wall _ <<<"$(render "$work/img.exr" --spp "$spp" --noise-threshold 0)"
    noisy+=("$spp $wall - $(rmse "$work/ref.exr" "$work/img.exr")")
  done
  for ((spp = 1; spp <= max_spp; spp *= 2)); do
    read -r wall dn <<<"$(render "$work/img.exr" --spp "$spp" --noise-threshold 0 --denoise)"
    e=$(rmse "$work/ref.exr" "$work/img.exr")
    denoised+=("$spp $wall $dn $e $(mean_change "$work/ref.exr" "$work/img.exr")")
    awk -v e="$e" 'BEGIN { exit !(e < 0.004) }' && break
  done
  for t in 0.08 0.04 0.02 0.01 0.005; do
    read -r wall dn <<<"$(render "$work/img.exr" --spp "$ref_spp" --noise-threshold "$t" --denoise)"
    e=$(rmse "$work/ref.exr" "$work/img.exr")
    adaptive+=("$t $wall $dn $e $(mean_change "$work/ref.exr" "$work/img.exr")")
    awk -v e="$e" 'BEGIN { exit !(e < 0.004) }' && break
    awk -v w="$wall" -v r="$ref_wall" 'BEGIN { exit !(w > 0.5 * r) }' && break
  done
  # The equal-time pair: --denoise at PAIR_SPP, and without at the spp the noisy ladder's longest
  # render says takes as long.
  pair_spp=${PAIR_SPP:-8}
  read -r pair_denoised _ <<<"$(render "$work/pair-d.exr" --spp "$pair_spp" --noise-threshold 0 --denoise)"
  pair_noisy_spp=$(tail -n 1 <<<"$(printf '%s\n' "${noisy[@]}")" |
    awk -v t="$pair_denoised" -v m="$pair_spp" '{ s = int(t * $1 / $2 + 0.5); print (s > m ? s : m) }')
  read -r pair_noisy _ <<<"$(render "$work/pair-n.exr" --spp "$pair_noisy_spp" --noise-threshold 0)"
  # The same renders again as PNG (the same seed: the same images, tone-mapped as tracer writes them).
  render "$O/denoise-$name-denoised.png" --spp "$pair_spp" --noise-threshold 0 --denoise >/dev/null
  render "$O/denoise-$name-noisy.png" --spp "$pair_noisy_spp" --noise-threshold 0 >/dev/null
  {
    echo "$name, ${size}x${size}, path, $threads threads, whole-process wall seconds ($($T --version | head -1))."
    echo "RMSE of the display values (exposure $exposure) against tracer's own $ref_spp-spp reference (seed 99,"
    echo "$ref_wall s); its own RMSE, from the last noisy render: $(tail -n 1 <<<"$(printf '%s\n' "${noisy[@]}")" |
      awk -v ref="$ref_spp" '{ printf "about %.5f", $4 / sqrt(1 + ref / $1) }')."
    echo
    echo "| spp | noisy: wall s | RMSE | denoised: wall s | of which denoising | RMSE | mean against the reference |"
    echo "|---:|---:|---:|---:|---:|---:|---:|"
    for ((spp = 1; spp <= max_spp; spp *= 2)); do
      n=$(printf '%s\n' "${noisy[@]}" | awk -v s="$spp" '$1 == s { printf "%.2f | %.5f", $2, $4 }')
      d=$(printf '%s\n' "${denoised[@]}" | awk -v s="$spp" '$1 == s { printf "%.2f | %.2f | %.5f | %+.2f %%", $2, $3, $4, $5 }')
      [[ -z $n && -z $d ]] && continue
      echo "| $spp | ${n:-– | –} | ${d:-– | – | – | –} |"
    done
    echo
    echo "Adaptive sampling with --denoise (at most $ref_spp spp):"
    echo
    echo "| threshold | wall s | of which denoising | RMSE | mean against the reference |"
    echo "|---:|---:|---:|---:|---:|"
    printf '%s\n' "${adaptive[@]}" | awk '{ printf "| %s | %.2f | %.2f | %.5f | %+.2f %% |\n", $1, $2, $3, $4, $5 }'
    echo
    read -r -a tn <<<"$(printf '%s\n' "${noisy[@]}" | seconds_to_rmse 0.02 0.01 0.005)"
    read -r -a td <<<"$(printf '%s\n' "${denoised[@]}" | seconds_to_rmse 0.02 0.01 0.005)"
    read -r -a ta <<<"$(printf '%s\n' "${adaptive[@]}" | seconds_to_rmse 0.02 0.01 0.005)"
    echo "| RMSE | noisy, fixed | denoised, fixed | denoised, adaptive |"
    echo "|---:|---:|---:|---:|"
    targets=(0.02 0.01 0.005)
    for i in 0 1 2; do echo "| ${targets[$i]} | ${tn[$i]} | ${td[$i]} | ${ta[$i]} |"; done
    echo
    echo "Equal time: denoise-$name-denoised.png, $pair_spp spp with --denoise, $pair_denoised s, RMSE" \
      "$(rmse "$work/ref.exr" "$work/pair-d.exr"); denoise-$name-noisy.png, $pair_noisy_spp spp without," \
      "$pair_noisy s, RMSE $(rmse "$work/ref.exr" "$work/pair-n.exr")."
  } | tee "$O/denoise-$name.md"
done
