#!/usr/bin/env bash
# Build time of the default accelerator (bvh8, built directly 8-wide) against Embree's, cold: each
# a fresh `tracer render --stats-json` process (its build_ms), 1 and 2 threads, on the generated
# scenes of 100k to 5M triangles (bench/make-scene.sh) and the largest scenes of views.tsv. Three
# runs per cell, the two accelerators interleaved; the table gives the medians and their ratio.
# Both build at QUALITY (default medium; QUALITY=high: spatial splits, Embree's HIGH).
# Writes docs/bench/build-scale.md and build-scale.tsv (-high.md, -high.tsv); about 6 minutes on 2 cores.
source "$(dirname "$0")/bench-prelude.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
runs=${RUNS:-3}
quality=${QUALITY:-medium}
out=build-scale$([ "$quality" = medium ] || echo "-$quality")

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# measure NAME VIEWS: one row per thread count.
measure() {
  local name=$1 views=$2 th a r tris
  for th in 1 2; do
    : > "$work/bvh8" && : > "$work/embree"
    for ((r = 0; r < runs; r++)); do
      for a in bvh8 embree; do
        $T render --view "$name" --views "$views" --integrator ao --accel "$a" --build-quality "$quality" \
          --width 64 --height 64 --spp 1 --threads $th -q --stats-json "$work/s.json" -o "$work/o.png"
        field "$work/s.json" build_ms >> "$work/$a"
        tris=$(field "$work/s.json" triangles)
      done
    done
    echo -e "$name\t$tris\t$th\t$(median < "$work/bvh8")\t$(median < "$work/embree")\t$(sort -g "$work/bvh8" | head -1)\t$(sort -g "$work/embree" | head -1)" >> "$O/$out.tsv"
  done
}

echo -e "scene\ttriangles\tthreads\tbvh8_ms\tembree_ms\tbvh8_min_ms\tembree_min_ms" > "$O/$out.tsv"
for v in sponza sibenik bunny; do measure "$v" ../shared/scenes/views.tsv; done
for n in 100000 300000 1000000 2000000 5000000; do
  bench/make-scene.sh $n "$work/gen-$n.obj" "$work/gen-$n.tsv" >/dev/null
  measure "gen-$n" "$work/gen-$n.tsv"
  rm "$work/gen-$n.obj"
done

awk -F'\t' 'NR == 1 {
  print "| scene | triangles | threads | build ms, bvh8 / Embree (median of '"$runs"') | ratio | fastest, bvh8 / Embree |"
  print "|---|---:|---:|---:|---:|---:|"; next }
{ printf "| %s | %d | %d | %.1f / %.1f | %.2fx | %.1f / %.1f |\n", $1, $2, $3, $4, $5, $4 / $5, $6, $7 }' \
  "$O/$out.tsv" > "$O/$out.md"
cat "$O/$out.md"
