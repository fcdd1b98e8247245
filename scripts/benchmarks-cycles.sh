#!/usr/bin/env bash
# Time to a clean image, tracer beside Blender's Cycles (issue 40). For each scene both renderers
# render the same OBJ, camera and materials (scripts/cycles/scene.py rebuilds tracer's material
# model as Cycles nodes), to linear EXR, and the script reports for each:
#   - its converged reference (REF_SPP samples, seed 99) and the two references' mean radiance,
#     which must agree within 1 % (printed; the run fails otherwise);
#   - fixed spp (16, 32, ... up to MAX_SPP) and adaptive sampling (tracer --noise-threshold,
#     Cycles' adaptive threshold, at most REF_SPP samples; each renderer's default is adaptive on;
#     the ladder stops once a render takes 0.8x the reference's time), each render's whole-
#     process wall time and RMSE against the renderer's own reference, in display values
#     (`tracer compare --exposure 1.5`: tone-mapped, not rounded);
#   - samples per second, and seconds to RMSE 0.02 / 0.01 / 0.005, interpolated in log-log
#     between the renders that bracket it (a ladder stops once it is below 0.005);
#   - an equal-time pair of images: tracer at 64 spp and Cycles at the spp that takes it as long,
#     both tone-mapped as tracer's PNG (docs/bench/cycles-SCENE-{tracer,cycles}.png);
#   - then tracer with --denoise on the same scenes (scripts/benchmarks-denoise.sh; DENOISE=0: not).
# Never part of CI or the quick start: Blender is a benchmark-only dependency.
#   scripts/benchmarks-cycles.sh [--install] [SCENE ...]
#       --install: apt-get install Debian's blender first (Cycles with Embree inside)
#       scenes: cornell-original cornell-water sponza-sky (the default: all three)
#   SIZE=512 THREADS=2 REF_SPP=1024 MAX_SPP=512    the defaults
# Sponza's bump maps are left out on both sides: tracer differences the height over one texel,
# Cycles (as pbrt-v4) over the pixel's footprint, and with them the converged images differ by
# 17 % in mean radiance at 512x512 (docs/BENCHMARKS.md section 18).
# Writes docs/bench/cycles-SCENE.md (cycles-SCENE-SIZE.md for another SIZE). About 20 minutes for
# each Cornell box at 512x512 on 2 cores, 9 for Sponza at 256x256.
if [[ ${1:-} == --install ]]; then
  shift
  command -v blender >/dev/null || { apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q blender; }
fi
source "$(dirname "$0")/bench-prelude.sh"
command -v blender >/dev/null || { echo "benchmarks-cycles: no blender (scripts/benchmarks-cycles.sh --install)" >&2; exit 2; }
size=${SIZE:-512} threads=${THREADS:-2} ref_spp=${REF_SPP:-1024} max_spp=${MAX_SPP:-512}
exposure=1.5
label=""
[[ $size == 512 ]] || label="-$size"
shared=$(cd "${SHARED:-../shared}" && pwd)
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell-original cornell-water sponza-sky)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
blender_run() { blender -b --factory-startup -noaudio --python "$@"; }
now() { date +%s.%N; }

# The scene of a benchmark, as both renderers take it: obj eye look up fov sky.
scene_of() {
  case $1 in
    cornell-original | cornell-water)
      awk -F'\t' -v v="$1" -v s="$shared/scenes" '$1 == v { print s "/" $2, $3, $4, $5, $6, "0,0,0" }' \
        "$shared/scenes/views.tsv" ;;
    sponza-sky)
      # A copy of the folder (links to its textures) whose MTL has no bump maps: see above.
      obj=$(sponza_without_bumps "$work" "$shared")
      awk -F'\t' -v o="$obj" '$1 == "sponza" { print o, $3, $4, $5, $6, "1,1,1" }' "$shared/scenes/views.tsv" ;;
    *) echo "unknown scene $1" >&2; return 2 ;;
  esac
}

# render RENDERER SPP THRESHOLD SEED OUT.exr: prints "wall_seconds render_seconds".
render() {
  local who=$1 spp=$2 threshold=$3 seed=$4 out=$5 start end
  start=$(now)
  if [[ $who == tracer ]]; then
    $T render "$obj" "--eye=$eye" "--look=$look" "--up=$up" --fov "$fov" --env "$sky" \
      --integrator path --width "$size" --height "$size" --threads "$threads" --spp "$spp" \
      --noise-threshold "$threshold" --seed "$seed" -q -o "$out" --exr float --stats-json "$work/s.json"
    end=$(now)
    echo "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }') $(awk -v m="$(field "$work/s.json" render_ms)" 'BEGIN { print m / 1000 }')"
  else
    blender_run scripts/cycles/scene.py -- --obj "$obj" --out "$out" --size "$size" --spp "$spp" \
      --threshold "$threshold" --seed "$seed" --threads "$threads" "--eye=$eye" "--look=$look" "--up=$up" \
      --fov "$fov" "--env=$sky" >"$work/cycles.log" 2>&1 || { cat "$work/cycles.log" >&2; return 1; }
    end=$(now)
    echo "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }') $(sed -n 's/^cycles-scene: render \([0-9.]*\) s.*/\1/p' "$work/cycles.log")"
  fi
}
rmse() { $T compare --exposure "$exposure" "$1" "$2" | sed -E 's/.*RMSE ([^,]*),.*/\1/'; }

for name in "${scenes[@]}"; do
  read -r obj eye look up fov sky <<<"$(scene_of "$name")"
  declare -A ref_time fixed adaptive thresholds
  thresholds[tracer]="0.04 0.02 0.01 0.005 0.0025"
  thresholds[cycles]="0.1 0.05 0.02 0.01 0.005"
  for who in tracer cycles; do
    read -r wall _ <<<"$(render "$who" "$ref_spp" 0 99 "$work/ref-$who.exr")"
    ref_time[$who]=$wall
    rows=()
    for ((spp = 16; spp <= max_spp; spp *= 2)); do
      read -r wall secs <<<"$(render "$who" "$spp" 0 0 "$work/img.exr")"
      e=$(rmse "$work/ref-$who.exr" "$work/img.exr")
      rows+=("$spp $wall $secs $e")
      [[ $spp == 64 ]] && cp "$work/img.exr" "$work/64-$who.exr"
      awk -v e="$e" 'BEGIN { exit !(e < 0.005) }' && break
    done
    fixed[$who]=$(printf '%s\n' "${rows[@]}")
    rows=()
    for t in ${thresholds[$who]}; do
      read -r wall secs <<<"$(render "$who" "$ref_spp" "$t" 0 "$work/img.exr")"
      e=$(rmse "$work/ref-$who.exr" "$work/img.exr")
      rows+=("$t $wall $secs $e")
      awk -v e="$e" 'BEGIN { exit !(e < 0.005) }' && break
      # Most pixels already ran to the reference's count: a lower threshold measures the reference.
      awk -v w="$wall" -v r="${ref_time[$who]}" 'BEGIN { exit !(w > 0.8 * r) }' && break
    done
    adaptive[$who]=$(printf '%s\n' "${rows[@]}")
  done
  means=$($T compare "$work/ref-tracer.exr" "$work/ref-cycles.exr")
  # The equal-time pair: Cycles at the spp its fixed ladder says takes as long as tracer's 64.
  t64=$(awk '$1 == 64 { print $2 }' <<<"${fixed[tracer]}")
  cycles_spp=$(awk -v t="$t64" '$1 == 16 { s16 = $2 } $1 == 64 { s64 = $2 }
    END { per = (s64 - s16) / 48; n = int((t - (s16 - 16 * per)) / per); print (n < 1 ? 1 : n) }' <<<"${fixed[cycles]}")
  read -r cycles_wall _ <<<"$(render cycles "$cycles_spp" 0 0 "$work/eq-cycles.exr")"
  for who in tracer cycles; do
    src=$work/64-tracer.exr
    [[ $who == cycles ]] && src=$work/eq-cycles.exr
    blender_run scripts/cycles/tonemap.py -- "$src" "$O/cycles-$name$label-$who.png" "$exposure" >/dev/null 2>&1
  done
  {
    echo "$name, ${size}x${size}, path, $threads threads, whole-process wall seconds ($($T --version | head -1);"
    echo "$(blender --version | head -1), CPU). RMSE of the display values (exposure $exposure) against each"
    echo "renderer's own $ref_spp-spp reference (seed 99)."
    echo
    echo "Converged references, linear: $means (tracer, then Cycles)."
    echo "References' wall time: tracer ${ref_time[tracer]} s, Cycles ${ref_time[cycles]} s."
    echo
    for who in tracer cycles; do
      echo "$who, fixed spp:"
      echo
      echo "| spp | wall s | render s | Msamples/s | RMSE |"
      echo "|---:|---:|---:|---:|---:|"
      awk -v px="$((size * size))" '{ printf "| %d | %.2f | %.2f | %.3f | %.5f |\n", $1, $2, $3, $1 * px / $3 / 1e6, $4 }' <<<"${fixed[$who]}"
      echo
      echo "$who, adaptive sampling (at most $ref_spp spp):"
      echo
      echo "| threshold | wall s | render s | RMSE |"
      echo "|---:|---:|---:|---:|"
      awk '{ printf "| %s | %.2f | %.2f | %.5f |\n", $1, $2, $3, $4 }' <<<"${adaptive[$who]}"
      echo
    done
    # The reference's own error, from the fixed ladder's last row: e(N)^2 = s^2/N + s^2/REF.
    for who in tracer cycles; do
      tail -n 1 <<<"${fixed[$who]}" | awk -v who="$who" -v ref="$ref_spp" \
        '{ printf "%s reference'"'"'s own RMSE: about %.5f (from %d spp)\n", who, $4 / sqrt(1 + ref / $1), $1 }'
    done
    echo
    read -r -a tf <<<"$(seconds_to_rmse 0.02 0.01 0.005 <<<"${fixed[tracer]}")"
    read -r -a cf <<<"$(seconds_to_rmse 0.02 0.01 0.005 <<<"${fixed[cycles]}")"
    read -r -a ta <<<"$(seconds_to_rmse 0.02 0.01 0.005 <<<"${adaptive[tracer]}")"
    read -r -a ca <<<"$(seconds_to_rmse 0.02 0.01 0.005 <<<"${adaptive[cycles]}")"
    ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (a ~ /^[0-9.]+$/ && b ~ /^[0-9.]+$/) printf "%.2f", a / b; else print "-" }'; }
    echo "| RMSE | tracer, adaptive (default) | Cycles, adaptive (default) | ratio | tracer, fixed | Cycles, fixed | ratio |"
    echo "|---:|---:|---:|---:|---:|---:|---:|"
    targets=(0.02 0.01 0.005)
    for i in 0 1 2; do
      echo "| ${targets[$i]} | ${ta[$i]} | ${ca[$i]} | $(ratio "${ta[$i]}" "${ca[$i]}") | ${tf[$i]} | ${cf[$i]} | $(ratio "${tf[$i]}" "${cf[$i]}") |"
    done
    echo
    median_rate() {
      awk -v px="$((size * size))" '{ printf "%.4f\n", $1 * px / $3 / 1e6 }' | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
    }
    tm=$(median_rate <<<"${fixed[tracer]}")
    cm=$(median_rate <<<"${fixed[cycles]}")
    echo "Msamples/s (median of the fixed renders): tracer $tm, Cycles $cm, ratio $(ratio "$tm" "$cm")."
    echo "Equal time: tracer 64 spp in ${t64} s, Cycles $cycles_spp spp in ${cycles_wall} s (cycles-$name$label-*.png)."
  } | tee "$O/cycles-$name$label.md"
  # The references must agree: the two renderers converge to the same image.
  awk '{ for (i = 1; i <= NF; ++i) if ($i ~ /^\(/) { v = substr($i, 2) + 0; exit !(v <= 1 && v >= -1) } exit 1 }' <<<"$means" ||
    { echo "benchmarks-cycles: $name: the references' means differ by more than 1 %: $means" >&2; exit 1; }
  unset ref_time fixed adaptive thresholds
done

# tracer with --denoise in the same run (the same machine state as Cycles' ladders above):
# scripts/benchmarks-denoise.sh on the same scenes, size and threads (DENOISE=0 leaves it out).
if [[ ${DENOISE:-1} != 0 ]]; then
  SIZE=$size THREADS=$threads "$(dirname "$0")/benchmarks-denoise.sh" "${scenes[@]}"
fi
