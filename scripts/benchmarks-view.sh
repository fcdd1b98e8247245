#!/usr/bin/env bash
# tracer view in the browser (docs/BENCHMARKS.md section 14): for every view of views.tsv at two
# threads, 512x512, path tracing (the view defaults), the time from a camera move to the first
# frame of the moved camera on screen, frames per second while dragging and at rest, measured in
# headless Chromium by bench/view-latency.mjs. Writes docs/bench/view.md.
source "$(dirname "$0")/bench-prelude.sh"
[[ -d tests/browser/node_modules/playwright-core ]] || npm ci --prefix tests/browser --no-audit --no-fund
out=$O/view.md
{
  echo "# tracer view, measured in the browser"
  echo
  echo "$(date -u +%Y-%m-%d), $(nproc) cores, headless Chromium on the same machine, \`tracer view --view V --threads 2\`"
  echo "(512x512, path tracing, 64 spp target). Command: \`scripts/benchmarks-view.sh\`."
  echo
  node bench/view-latency.mjs "$T" ../shared/scenes/views.tsv 2
} | tee "$out"
