#!/usr/bin/env bash
# The path tracer's figures behind docs/BENCHMARKS.md section 8 (about 25 minutes on 2 cores):
# path-traced rays through the 8-wide BVH and through Embree's single-ray API on every view, at 1
# and 2 threads; then the time the Cornell Original takes at 1024x1024 to reach a noise level,
# as RMSE against a 2048-spp reference, with NEE+MIS and with BSDF sampling alone.
# Run from the project root with ../shared/scenes beside it, on an otherwise idle machine;
# scripts/benchmarks.sh runs it too. Outputs go to docs/bench/.
source "$(dirname "$0")/bench-prelude.sh"

for t in 1 2; do
  $T bench --integrator path --spp 16 --scenes all --variants bvh8,embree --size 512x512 --runs 3 --best 2 \
    --threads $t --max-seconds 300 --json "$O/path-t$t.json" --markdown "$O/path-t$t.md"
done

# Time to a noise level: the reference, then each spp's render time and RMSE against it.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=../shared/scenes/cornell-box/CornellBox-Original.obj
common=(--width 1024 --height 1024 -q --exr float)
$T render "$scene" "${common[@]}" --spp 2048 --seed 99 -o "$work/ref.exr"
{
  echo "Cornell Original, 1024x1024, 2 threads; RMSE of linear radiance against a 2048-spp render (seed 99)"
  echo
  echo "| light sampling | spp | render s | RMSE |"
  echo "|---|---:|---:|---:|"
  for ls in mis bsdf; do
    for spp in 4 16 64 256; do
      $T render "$scene" "${common[@]}" --spp $spp --light-sampling $ls -o "$work/img.exr" --stats-json "$work/s.json"
      ms=$(grep -o '"render_ms": [0-9.e+-]*' "$work/s.json" | awk '{print $2}')
      rmse=$($T compare "$work/ref.exr" "$work/img.exr" | sed -E 's/.*RMSE ([^,]*),.*/\1/')
      printf '| %s | %d | %.2f | %s |\n' "$ls" "$spp" "$(awk "BEGIN{print $ms / 1000}")" "$rmse"
    done
  done
} | tee "$O/convergence.md"
