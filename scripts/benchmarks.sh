#!/usr/bin/env bash
# Regenerates every figure behind docs/BENCHMARKS.md on this machine (about 50 minutes on 2 cores):
# the study's table, the scheduler scaling at 1 and 2 threads, the per-task overhead, our variants
# with Embree on all scenes, the Google Benchmark microbenchmarks, then path tracing beside Embree
# (scripts/benchmarks-path.sh), tracer-mpi (scripts/benchmarks-mpi.sh) and the scaling from 100k to
# 5M triangles (scripts/benchmarks-scale.sh), builds (scripts/benchmarks-build.sh), loading (scripts/benchmarks-load.sh), the viewer (scripts/benchmarks-view.sh), ray streams (scripts/benchmarks-streams.sh). Outputs go to docs/bench/.
# Run from the project root with ../shared/scenes beside it, on an otherwise idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release >/dev/null
cmake --build --preset release
T=build/release/tracer
O=docs/bench
mkdir -p "$O"

{
  echo "# Machine"
  echo
  echo '```'
  lscpu | grep -E "Model name|^CPU\(s\)|Thread|MHz|L1d|L2|L3|Flags" | sed 's/Flags:.*avx512f.*/Flags: ... avx2 avx512f ... (AVX-512 capable)/'
  free -h | head -2
  echo "compiler: $(c++ --version | head -1)"
  echo "embree: $(dpkg-query -W -f='${Version}' libembree-dev 2>/dev/null), tbb: $(dpkg-query -W -f='${Version}' libtbb-dev 2>/dev/null)"
  echo "SIMD target chosen by tracer: $($T render --accel bvh8 --width 4 --height 4 -q --stats -o /tmp/tracer-target.png | grep accel)"
  echo "date: $(date -u +%Y-%m-%d)"
  echo '```'
} > "$O/machine.md"

# The views people render, against Embree's single rays and its packet API, at 1 and 2 threads.
for t in 1 2; do
  $T bench --scenes all --variants tbb+sah,bvh8,best,embree,embree-packets --size 1024x1024 --ao 16 --runs 3 --best 2 \
    --threads $t --max-seconds 300 --json "$O/views-t$t.json" --markdown "$O/views-t$t.md"
done

# 1. The study's table: its ten variants (simd-brute is its ISPC column) plus ours and Embree.
$T bench --scenes cornell --framed --variants study,sah,tbb+sah,best,embree --size 128x128 --ao 4 --runs 10 --best 3 \
  --max-seconds 300 --json "$O/study.json" --markdown "$O/study.md" --plot "$O/study.svg"

# The study's ISPC column: brute force eight triangles per SIMD pass, one thread.
$T bench --scenes cornell --framed --variants seq,simd-brute --size 128x128 --ao 4 --runs 10 --best 3 --max-seconds 300 --markdown "$O/simd-brute.md"

# 2. Schedulers at 1 and 2 threads (SAH BVH), and the per-task overhead on a near-empty scene.
for t in 1 2; do
  $T bench --scenes cornell,sponza --framed --variants sah,async+sah,lq+sah,atomic+sah,tbb+sah \
    --size 512x512 --ao 16 --runs 5 --best 3 --threads $t --max-seconds 300 --json "$O/sched-t$t.json" --markdown "$O/sched-t$t.md"
done
$T bench --scenes "$O/near-empty.obj" --variants sah,async+sah,lq+sah,atomic+sah,tbb+sah --size 2048x2048 --ao 0 \
  --runs 5 --best 3 --threads 2 --max-seconds 300 --markdown "$O/overhead.md"

# 3. Our trees against Embree on every scene, at 1 and 2 threads; then the SIMD issue's workload
#    (1024x1024, 16 AO rays) for the 8-wide BVH with and without primary-ray packets.
for t in 1 2; do
  $T bench --scenes cornell,large --framed --variants bvh,sah,tbb+sah,bvh8,best,embree --size 512x512 --ao 16 --runs 5 --best 3 --threads $t --max-seconds 300 \
    --json "$O/embree-t$t.json" --markdown "$O/embree-t$t.md" --plot "$O/embree-t$t.svg"
done
for t in 1 2; do
  $T bench --scenes cornell,large --framed --variants bvh8,best,embree --size 1024x1024 --ao 16 --runs 3 --best 2 --threads $t --max-seconds 300 \
    --json "$O/simd-1024-t$t.json" --markdown "$O/simd-1024-t$t.md"
done

# 4. Microbenchmarks: build times per split/builder, Mrays/s per ray type, bytes per triangle.
#    Traversal five times over: docs/BENCHMARKS.md quotes the best of the five for each row, as
#    `tracer bench` keeps its best runs (this shared VM has bursts of slowdown).
build/release/bench/tracer_microbench --benchmark_min_time=0.3 --benchmark_format=console \
  --benchmark_filter='BM_TriangleTest|BM_BoxTest|BM_BvhBuild/(Sphere|Water|Sponza|Sibenik|Bunny)/' \
  2>/dev/null | tee "$O/microbench.txt"
build/release/bench/tracer_microbench --benchmark_min_time=0.3 --benchmark_format=console --benchmark_repetitions=5 \
  --benchmark_filter='BM_Traverse/(Original|Sphere|Water|Sponza|Sibenik|Bunny)/|BM_Primary1024/(Original|Sphere|Water|Sponza|Sibenik|Bunny)/' \
  2>/dev/null | tee "$O/traversal.txt"
# Builds per scene, split and builder, five repetitions each (medians for section 4).
build/release/bench/tracer_microbench --benchmark_filter='BM_BvhBuild/(Sphere|Water|Sponza|Sibenik)/' \
  --benchmark_repetitions=5 --benchmark_report_aggregates_only=true 2>/dev/null | tee "$O/build-all.txt"
# The BVH issue's build target: the Bunny's SAH build against Embree's, twelve repetitions each
# (single builds on this shared VM vary by several milliseconds; compare minima and medians).
build/release/bench/tracer_microbench --benchmark_filter='BM_BvhBuild/Bunny/(sah/(seq|tbb)|embree)' \
  --benchmark_repetitions=12 --benchmark_format=console 2>/dev/null | tee "$O/build-bunny.txt"
# Incoherent rays on the views, traversal only: bounces and AO rays, single and sorted (section 8).
build/release/bench/tracer_microbench --benchmark_filter='BM_Incoherent/' --benchmark_repetitions=3 \
  --benchmark_report_aggregates_only=true 2>/dev/null | grep _median | tee "$O/incoherent.txt"
# 5. The path tracer: incoherent rays beside Embree, and time to a noise level.
scripts/benchmarks-path.sh
# 6. tracer-mpi: the same render as 1 rank x 2 threads and 2 ranks x 1 thread.
scripts/benchmarks-mpi.sh
scripts/benchmarks-scale.sh
scripts/benchmarks-build.sh
# 7. Loading: the OBJ parser against tinyobjloader.
scripts/benchmarks-load.sh
# 8. tracer view in the browser: move to frame, frames per second.
scripts/benchmarks-view.sh
# 9. Ray streams: the AO workload's rays sorted per 16x16 pixels, beside Embree's stream API.
scripts/benchmarks-streams.sh
echo "figures written to $O/"
