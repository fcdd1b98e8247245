#!/usr/bin/env bash
# tracer-mpi's figures behind docs/BENCHMARKS.md section 9 (about 5 minutes on 2 cores): the same
# render as one process with 2 threads, as 1 rank x 2 threads and as 2 ranks x 1 thread, on the
# four Cornell views and Sponza, for ao and for path; the render time, and rank 0's time spent
# answering tile requests. Run from the project root with ../shared/scenes beside it, on an
# otherwise idle machine; scripts/benchmarks.sh runs it too. Output: docs/bench/mpi.md.
source "$(dirname "$0")/bench-prelude.sh"
M=build/release/tracer-mpi
# --bind-to none: with two ranks or fewer Open MPI binds each rank to one core, which would make
# "1 rank x 2 threads" share one core.
MPIRUN=(mpirun --oversubscribe --bind-to none)
[[ $(id -u) -eq 0 ]] && MPIRUN+=(--allow-run-as-root)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The best (lowest) render_ms of three runs of a command that writes --stats-json to $work/s.json.
best_of_three() {
  local best=""
  for _ in 1 2 3; do
    "$@" >/dev/null 2>&1
    local ms
    ms=$(field "$work/s.json" render_ms)
    if [[ -z $best ]] || awk "BEGIN{exit !($ms < $best)}"; then best=$ms; fi
  done
  echo "$best"
}

{
  echo "512x512; render ms, best of 3; tiles of 16x16 (1,024 per pass); rank 0's messages (requests, returned tiles, done) and its time per message"
  echo
  echo "| view | workload | tracer, 2 threads | 1 rank x 2 threads | 2 ranks x 1 thread | 2 ranks / tracer | messages | rank 0 us per message |"
  echo "|---|---|---:|---:|---:|---:|---:|---:|"
  for view in cornell-original cornell-mirror cornell-sphere cornell-water sponza; do
    for workload in "ao:--integrator ao" "path:--integrator path --spp 16"; do
      name=${workload%%:*}
      flags=(--view "$view" ${workload#*:} --width 512 --height 512 -q -o "$work/x.png" --stats-json "$work/s.json")
      one=$(best_of_three "$T" render "${flags[@]}" --threads 2)
      r1=$(best_of_three "${MPIRUN[@]}" -np 1 "$M" render "${flags[@]}" --threads 2)
      r2=$(best_of_three "${MPIRUN[@]}" -np 2 "$M" render "${flags[@]}" --threads 1)
      requests=$(field "$work/s.json" rank0_messages)
      per=$(field "$work/s.json" rank0_us_per_message)
      printf '| %s | %s | %.1f | %.1f | %.1f | %.2fx | %s | %.1f |\n' "$view" "$name" "$one" "$r1" "$r2" \
        "$(awk "BEGIN{print $r2 / $one}")" "$requests" "$per"
    done
  done
} | tee "$O/mpi.md"

# Rank 0's cost per request against the tile size (the payload it adds grows with the tile).
{
  echo
  echo "Sponza, path, 16 spp, 512x512, 2 ranks x 1 thread: rank 0's time per message by tile size"
  echo
  echo "| tile | messages | rank 0 us per message | rank 0 ms in all | render ms |"
  echo "|---:|---:|---:|---:|---:|"
  for tile in 8 16 32 64; do
    "${MPIRUN[@]}" -np 2 "$M" render --view sponza --integrator path --spp 16 --width 512 --height 512 --tile $tile \
      --threads 1 -q -o "$work/x.png" --stats-json "$work/s.json" >/dev/null 2>&1
    printf '| %d | %s | %.1f | %.1f | %.1f |\n' "$tile" "$(field "$work/s.json" rank0_messages)" \
      "$(field "$work/s.json" rank0_us_per_message)" "$(field "$work/s.json" rank0_message_ms)" \
      "$(field "$work/s.json" render_ms)"
  done
} | tee -a "$O/mpi.md"
