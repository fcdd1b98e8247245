#!/usr/bin/env bash
# How load, build, render and memory grow with the triangle count: generated scenes of 100k to
# 100M unique triangles (bench/make-scene.sh: the same 400 spheres, finer each time) and the
# largest scenes of views.tsv, the default accelerator (bvh8, packets and bundles) beside Embree's
# packet API, 2 threads, 1024x1024, 16 AO rays. Load is tracer's loader against tinyobjloader's own
# parse of the file (bench/load_time.cpp; one run from 20M up, three below). Peak memory is each
# process's peak resident set. 200M is tried too: past this machine's memory, tracer refuses it
# with its estimate (the row says so). Then instanced totals of 10^8, 10^9 and 10^10 triangles (the
# Bunny placed 700, 7,000 and 70,000 times, bench/make_instances.cpp), tracer's two-level tree
# beside Embree's instances. Writes docs/bench/scale.md, scale.tsv, scale-instanced.tsv and
# scale.svg; about 20 minutes on 2 cores, 17 GiB of disk for the generated files (one at a time).
source "$(dirname "$0")/bench-prelude.sh"
L=build/release/bench/tracer_load_time
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT


# measure NAME VIEWS OBJ: one row of scale.tsv.
measure() {
  local name=$1 views=$2 obj=$3 load tiny a runs=3
  [[ $(stat -c %s "$obj") -gt 500000000 ]] && runs=1
  load=$($L "$obj" --runs $runs --threads 2)
  tiny=$(sed 's/.*"tinyobjloader_ms": \([0-9.]*\).*/\1/' <<<"$load")
  load=$(sed 's/.*"tracer_ms": \([0-9.]*\).*/\1/' <<<"$load")
  local row="$name"
  for a in bvh8 embree; do
    $T render --view "$name" --views "$views" --integrator ao --ao 16 --accel "$a" --width 1024 --height 1024 \
      --threads 2 -q --max-input-mib 16384 --stats-json "$work/$a.json" -o "$work/$a.png"
  done
  row+="\t$(field "$work/bvh8.json" triangles)\t$load\t$tiny"
  for k in build_ms render_ms mrays_per_s peak_rss_mib accel_bytes; do
    row+="\t$(field "$work/bvh8.json" $k)\t$(field "$work/embree.json" $k)"
  done
  echo -e "$row" >> "$O/scale.tsv"
}

echo -e "scene\ttriangles\tload_ms\ttinyobjloader_ms\tbuild_ms\tembree_build_ms\trender_ms\tembree_render_ms\tmrays\tembree_mrays\tpeak_mib\tembree_peak_mib\taccel_bytes\tembree_accel_bytes" > "$O/scale.tsv"
for n in 100000 300000 1000000 2000000 5000000 20000000 50000000 100000000; do
  bench/make-scene.sh $n "$work/gen-$n.obj" "$work/gen-$n.tsv" >/dev/null
  measure "gen-$n" "$work/gen-$n.tsv" "$work/gen-$n.obj"
  rm "$work/gen-$n.obj"
done
# 200M: more than this machine holds; tracer's answer (its estimate, once the OBJ is parsed) kept.
bench/make-scene.sh 200000000 "$work/gen-200000000.obj" "$work/gen-200000000.tsv" >/dev/null
# The peak resident set read from /proc while it runs (VmHWM only grows).
$T render --view gen-200000000 --views "$work/gen-200000000.tsv" --integrator ao --width 1024 --height 1024 \
  --threads 2 -q --max-input-mib 16384 -o "$work/big.png" 2>"$work/refusal.txt" &
pid=$! peak=0
while kill -0 $pid 2>/dev/null; do
  h=$(awk '/^VmHWM/ { print $2 }' /proc/$pid/status 2>/dev/null || true)
  [[ -n $h ]] && peak=$h
  sleep 0.2
done
wait $pid || true
refusal=$(head -1 "$work/refusal.txt")
refusal=${refusal//$work\//}
rm "$work/gen-200000000.obj"
echo -e "gen-200000000\t${refusal#tracer: error: }\t$((peak / 1024))" > "$O/scale-refused.tsv"

# Instanced: the Bunny placed N times, seen over the grid; load, build, render, memory.
M=build/release/bench/tracer_make_instances
echo -e "scene\tinstanced_triangles\tunique\tload_ms\tembree_load_ms\tbuild_ms\tembree_build_ms\trender_ms\tembree_render_ms\tmrays\tembree_mrays\tpeak_mib\tembree_peak_mib\taccel_bytes\tembree_accel_bytes" > "$O/scale-instanced.tsv"
for n in 700 7000 70000; do
  $M ../shared/scenes/bunny/bunny.obj $n "$work/bunny-$n.gltf" >/dev/null
  for a in bvh8 embree; do
    $T render "$work/bunny-$n.gltf" --integrator ao --ao 16 --accel "$a" --width 1024 --height 1024 --threads 2 -q \
      --eye -20,60,30 --look 250,0,-250 --stats-json "$work/$a.json" -o "$work/$a.png"
  done
  row="bunny-x$n\t$((144046 * n))\t144046"
  for k in load_ms build_ms render_ms mrays_per_s peak_rss_mib accel_bytes; do
    row+="\t$(field "$work/bvh8.json" $k)\t$(field "$work/embree.json" $k)"
  done
  echo -e "$row" >> "$O/scale-instanced.tsv"
  rm "$work/bunny-$n".*
done
for v in sponza sibenik bunny; do
  obj=$(awk -F'\t' -v v=$v '$1 == v { print $2 }' ../shared/scenes/views.tsv)
  measure "$v" ../shared/scenes/views.tsv "../shared/scenes/$obj"
done

# The table, ratios as ours over Embree's (load: over tinyobjloader's parse).
awk -F'\t' 'NR == 1 {
  print "| scene | triangles | load ms (tinyobjloader alone) | build ms, bvh8 / Embree | render ms, bvh8 / Embree | Mrays/s, bvh8 / Embree | peak MiB, bvh8 / Embree | accelerator bytes/tri, bvh8 / Embree |"
  print "|---|---:|---:|---:|---:|---:|---:|---:|"; next }
{ printf "| %s | %d | %.0f (%.0f, %.2fx) | %.0f / %.0f (%.2fx) | %.0f / %.0f (%.2fx) | %.2f / %.2f (%.2fx) | %.0f / %.0f (%.2fx) | %.1f / %.1f |\n",
    $1, $2, $3, $4, $3 / $4, $5, $6, $5 / $6, $7, $8, $7 / $8, $9, $10, $9 / $10, $11, $12, $11 / $12, $13 / $2, $14 / $2 }' \
  "$O/scale.tsv" > "$O/scale.md"
awk -F'\t' '{ printf "\n%s: refused, %s (peak resident set %s MiB)\n", $1, $2, $3 }' "$O/scale-refused.tsv" >> "$O/scale.md"
awk -F'\t' 'NR == 1 {
  print "\n| instanced scene | triangles placed (unique) | load ms, bvh8 / Embree | build ms, bvh8 / Embree | render ms, bvh8 / Embree | Mrays/s, bvh8 / Embree | peak MiB, bvh8 / Embree | accelerator MiB, bvh8 / Embree |"
  print "|---|---:|---:|---:|---:|---:|---:|---:|"; next }
{ printf "| %s | %.3g (%d) | %.0f / %.0f | %.0f / %.0f (%.2fx) | %.0f / %.0f (%.2fx) | %.2f / %.2f (%.2fx) | %.0f / %.0f (%.2fx) | %.1f / %.1f |\n",
    $1, $2, $3, $4, $5, $6, $7, $6 / $7, $8, $9, $8 / $9, $10, $11, $10 / $11, $12, $13, $12 / $13, $14 / 1048576, $15 / 1048576 }' \
  "$O/scale-instanced.tsv" >> "$O/scale.md"

# The plot: milliseconds against triangles, log-log, generated scenes only (same image at every size).
awk -F'\t' 'NR > 1 && $1 ~ /^gen-/ { n++; x[n] = $2; for (c = 3; c <= 8; c++) y[n, c] = $c }
END {
  W = 720; H = 440; L = 70; R = 200; B = 50; Tp = 20
  x0 = log(1e5) / log(10); x1 = log(1e8) / log(10); y0 = 0; y1 = 5
  printf "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" font-family=\"sans-serif\" font-size=\"12\">\n", W, H
  printf "<rect width=\"%d\" height=\"%d\" fill=\"white\"/>\n", W, H
  for (e = y0; e <= y1; e++) { py = Tp + (H - Tp - B) * (1 - (e - y0) / (y1 - y0))
    printf "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#ddd\"/><text x=\"%d\" y=\"%.1f\" text-anchor=\"end\">%g ms</text>\n", L, py, W - R, py, L - 6, py + 4, 10 ^ e }
  for (e = 5; e <= 8; e++) { px = L + (W - L - R) * (e - x0) / (x1 - x0)
    printf "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%d\" stroke=\"#ddd\"/><text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">%s triangles</text>\n", px, Tp, px, H - B, px, H - B + 18, (e == 5 ? "100k" : e == 6 ? "1M" : e == 7 ? "10M" : "100M") }
  split("load (tracer)|load (tinyobjloader alone)|build bvh8|build Embree|render bvh8|render Embree (packets)", name, "|")
  split("#1f77b4|#aec7e8|#d62728|#ff9896|#2ca02c|#98df8a", color, "|")
  for (c = 3; c <= 8; c++) { k = c - 2; pts = ""
    for (i = 1; i <= n; i++) { px = L + (W - L - R) * (log(x[i]) / log(10) - x0) / (x1 - x0)
      py = Tp + (H - Tp - B) * (1 - (log(y[i, c]) / log(10) - y0) / (y1 - y0)); pts = pts sprintf("%.1f,%.1f ", px, py)
      printf "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>\n", px, py, color[k] }
    printf "<polyline points=\"%s\" fill=\"none\" stroke=\"%s\" stroke-width=\"2\"%s/>\n", pts, color[k], (k % 2 == 0 ? " stroke-dasharray=\"6,3\"" : "")
    printf "<line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\" stroke=\"%s\" stroke-width=\"2\"%s/><text x=\"%d\" y=\"%d\">%s</text>\n", W - R + 12, Tp + 20 * k, W - R + 36, Tp + 20 * k, color[k], (k % 2 == 0 ? " stroke-dasharray=\"6,3\"" : ""), W - R + 42, Tp + 20 * k + 4, name[k] }
  printf "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">1024x1024, 16 AO rays, 2 threads; generated scenes (bench/make-scene.sh)</text>\n</svg>\n", (L + W - R) / 2, H - 8
}' "$O/scale.tsv" > "$O/scale.svg"
cat "$O/scale.md"
