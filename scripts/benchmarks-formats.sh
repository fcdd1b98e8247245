#!/usr/bin/env bash
# Loading each format: the same geometry as OBJ, glTF (.gltf + .bin), binary .glb, binary and
# ASCII PLY, loaded by tracer's importers, and the .glb and binary PLY by assimp beside them
# (bench/format_load.cpp; the files are written from the OBJ by tests/scene_writers.cpp). Scenes:
# the Bunny, Sponza, and generated scenes of 5M and 10M triangles (bench/make-scene.sh); 1 and 2
# threads; best of N runs. assimp is a benchmark-only dependency: installed here when missing.
# Writes docs/bench/formats.md; about 6 minutes on 2 cores.
if ! dpkg-query -W -f='${Status}' libassimp-dev 2>/dev/null | grep -q "install ok installed"; then
  echo "benchmarks-formats: installing libassimp-dev (the reference loader)" >&2
  ${SUDO:-$( [[ $(id -u) -eq 0 ]] || echo sudo)} apt-get install -y -qq --no-install-recommends libassimp-dev
  rm -f build/release/CMakeCache.txt  # so that the release preset finds it
fi
source "$(dirname "$0")/bench-prelude.sh"
F=build/release/bench/tracer_format_load
S=../shared/scenes
out=$O/formats.md
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

num() { sed "s/.*\"$2\": \([0-9.]*\).*/\1/" <<<"$1"; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }

files=("$S/bunny/bunny.obj" "$S/sponza/sponza.obj")
for n in 5000000 10000000; do
  bench/make-scene.sh "$n" "$work/gen-$n.obj" "$work/gen-$n.tsv" >/dev/null
  files+=("$work/gen-$n.obj")
done
{
  echo "| scene | triangles | threads | OBJ ms | .gltf ms | .glb ms | PLY binary ms | PLY ASCII ms | .glb / OBJ | PLY binary / OBJ | assimp .glb ms | assimp PLY binary ms | assimp / tracer, .glb | assimp / tracer, PLY |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
  for f in "${files[@]}"; do
    runs=5
    [[ $(stat -c %s "$f") -gt 50000000 ]] && runs=3
    for t in 1 2; do
      r=$($F "$f" --runs $runs --threads $t)
      o=$(num "$r" obj_ms) g=$(num "$r" gltf_ms) b=$(num "$r" glb_ms) p=$(num "$r" ply_binary_ms) a=$(num "$r" ply_ascii_ms)
      ab=$(num "$r" assimp_glb_ms) ap=$(num "$r" assimp_ply_binary_ms)
      echo "| $(basename "$f" .obj) | $(num "$r" triangles) | $t | $o | $g | $b | $p | $a | $(ratio "$b" "$o")× | $(ratio "$p" "$o")× | $ab | $ap | $(ratio "$ab" "$b")× | $(ratio "$ap" "$p")× |"
    done
  done
} > "$out"
cat "$out"
