#!/usr/bin/env bash
# Ray streams (issue 54): the AO workload on every view of views.tsv at 1024x1024, 1 and 2
# threads, with tracer's AO rays in bundles (best) and in sorted streams (best-streams), beside
# Embree's packet API (embree-packets) and its stream API on the same sorted rays
# (embree-streams); best 2 of 3 runs. Then path tracing 512x512, 16 spp inside Sponza and
# Sibenik against Embree's single rays. Writes docs/bench/streams-{1,2}t.md and streams-path.md;
# about 12 minutes on 2 cores. The per-ray counts beside them: docs/BENCHMARKS.md, section 23.
source "$(dirname "$0")/bench-prelude.sh"
for threads in 1 2; do
  $T bench --scenes all --variants best,best-streams,embree-packets,embree-streams --threads "$threads" \
    --size 1024x1024 --runs 3 --best 2 --max-seconds 60 --markdown "$O/streams-${threads}t.md" >/dev/null
done
$T bench --scenes sponza,sibenik --integrator path --spp 16 --variants bvh8,embree --threads 1 --size 512x512 \
  --runs 2 --best 1 --max-seconds 120 --markdown "$O/streams-path.md" >/dev/null
cat "$O"/streams-1t.md "$O"/streams-2t.md "$O"/streams-path.md
