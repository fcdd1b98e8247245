#!/usr/bin/env bash
# Loading: tracer's OBJ loader against tinyobjloader's own parse of the same file, on the scenes
# of ../shared and on generated scenes of 100k to 5M triangles, 1 and 2 threads
# (bench/load_time.cpp: best of N alternating runs in one process). "geometry" is the load
# without the textures, what tinyobjloader does; "whole" adds reading and decoding every map_Kd.
# Then, for the shared scenes, instructions of one geometry load and of one tinyobjloader parse,
# counted by valgrind (exact, where this VM's times move by tens of percent).
# Writes docs/bench/load.md; about 5 minutes on 2 cores.
source "$(dirname "$0")/bench-prelude.sh"
L=build/release/bench/tracer_load_time
S=../shared/scenes
out=docs/bench/load.md
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

num() { sed "s/.*\"$2\": \([0-9.]*\).*/\1/" <<<"$1"; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }

files=("$S/sponza/sponza.obj" "$S/sibenik/sibenik.obj" "$S/bunny/bunny.obj")
for n in 100000 1000000 5000000; do
  bench/make-scene.sh "$n" "$work/gen-$n.obj" "$work/gen-$n.tsv" >/dev/null
  files+=("$work/gen-$n.obj")
done

{
  echo "| scene | triangles | threads | geometry ms | whole load ms | tinyobjloader ms | geometry / tinyobjloader | whole / tinyobjloader |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|"
  for f in "${files[@]}"; do
    runs=9
    [[ $(stat -c %s "$f") -gt 50000000 ]] && runs=3
    for t in 1 2; do
      r=$($L "$f" --runs $runs --threads $t)
      g=$(num "$r" geometry_ms) w=$(num "$r" tracer_ms) o=$(num "$r" tinyobjloader_ms)
      echo "| $(basename "$f" .obj) | $(num "$r" triangles) | $t | $g | $w | $o | $(ratio "$g" "$o")× | $(ratio "$w" "$o")× |"
    done
  done
  echo
  echo "| scene | instructions, geometry load | instructions, tinyobjloader | ratio |"
  echo "|---|---:|---:|---:|"
  for f in "${files[@]:0:3}"; do
    count() { valgrind --tool=callgrind --callgrind-out-file=/dev/null "$L" "$f" --once "$1" 2>&1 |
        sed -n 's/.*refs: *\([0-9,]*\).*/\1/p' | tr -d ,; }
    a=$(count geometry) b=$(count tinyobjloader)
    echo "| $(basename "$f" .obj) | $a | $b | $(ratio "$a" "$b")× |"
  done
} > "$out"
cat "$out"
