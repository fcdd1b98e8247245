#!/usr/bin/env bash
# Instanced against flattened, on scenes that fit both ways: Sponza placed 16 times (seen from
# inside the first, as views.tsv's Sponza view) and the Bunny placed 100 times (seen over the
# grid), written by bench/make_instances.cpp as glTF, once with instances and once with a mesh
# per placement (which tracer loads flat). Sponza is written two ways instanced: each of its 33
# geometries a mesh placed 16 times (sponza16: 528 overlapping instances), and as one mesh of 33
# primitives placed 16 times (sponza16-one: as an exporter writes one object). For each: tracer's bvh8 (two-level on the instanced
# file, the 8-wide BVH on the flat one) and Embree (instance geometry / flat), 512x512, 1 thread,
# AO (16 rays) and path (4 spp), best of 3 runs; load, build, Mrays/s, peak resident set and the
# accelerator's bytes. Then the 10^10-triangle scene (70,000 Bunnies) with bvh8. Writes
# docs/bench/instances.md and instances.tsv; about 6 minutes on 2 cores.
source "$(dirname "$0")/bench-prelude.sh"
M=build/release/bench/tracer_make_instances
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
shared=${SHARED:-../shared}
$M "$shared/scenes/sponza/sponza.obj" 16 "$work/sponza16.gltf" >/dev/null
$M "$shared/scenes/sponza/sponza.obj" 16 "$work/sponza16-flat.gltf" --distinct >/dev/null
$M "$shared/scenes/sponza/sponza.obj" 16 "$work/sponza16-one.gltf" --one-mesh >/dev/null
$M "$shared/scenes/bunny/bunny.obj" 100 "$work/bunny100.gltf" >/dev/null
$M "$shared/scenes/bunny/bunny.obj" 100 "$work/bunny100-flat.gltf" --distinct >/dev/null
$M "$shared/scenes/bunny/bunny.obj" 70000 "$work/bunny70k.gltf" >/dev/null

# best FILE ARGS...: the best of 3 renders' stats (by Mrays/s) as "load build mrays peak accel".
best() {
  local file=$1 b="" m=0
  shift
  for run in 1 2 3; do
    $T render "$file" "$@" -q --threads 1 --width 512 --height 512 -o "$work/o.png" --stats-json "$work/s.json"
    local r
    r=$(field "$work/s.json" mrays_per_s)
    if awk -v a="$r" -v b="$m" 'BEGIN { exit !(a > b) }'; then
      m=$r
      b="$(field "$work/s.json" load_ms) $(field "$work/s.json" build_ms) $r $(field "$work/s.json" peak_rss_mib) $(field "$work/s.json" accel_bytes)"
    fi
  done
  echo "$b"
}

sponza_cam="--eye -15,3,0 --look 10,4,0"
bunny_cam="--eye -2,3,2 --look 9,0,-9"
echo -e "scene\tworkload\taccel\tload_ms\tbuild_ms\tmrays\tpeak_mib\taccel_bytes" > "$O/instances.tsv"
for scene in sponza16 bunny100; do
  cam=$sponza_cam forms=("" "-one" "-flat")
  [[ $scene == bunny100 ]] && cam=$bunny_cam forms=("" "-flat")
  for workload in "ao" "path --spp 4"; do
    for accel in bvh8 embree; do
      for form in "${forms[@]}"; do
        # shellcheck disable=SC2086
        row=$(best "$work/$scene$form.gltf" --accel $accel --integrator $workload $cam)
        echo -e "$scene$form\t${workload%% *}\t$accel\t${row// /\\t}" >> "$O/instances.tsv"
      done
    done
  done
done
# shellcheck disable=SC2086
row=$(best "$work/bunny70k.gltf" --integrator ao --eye -20,60,30 --look 250,0,-250)
echo -e "bunny70k\tao\tbvh8\t${row// /\\t}" >> "$O/instances.tsv"

awk -F'\t' 'NR == 1 {
  print "| scene | workload | accelerator | load ms | build ms | Mrays/s | peak MiB | accelerator MiB |"
  print "|---|---|---|---:|---:|---:|---:|---:|"; next }
{ printf "| %s | %s | %s | %.0f | %.1f | %.2f | %.0f | %.1f |\n", $1, $2, $3, $4, $5, $6, $7, $8 / 1048576 }' \
  "$O/instances.tsv" > "$O/instances.md"
cat "$O/instances.md"
