# Sourced first by every scripts/benchmarks*.sh: from the project root, the release preset built,
# T the tracer binary, O the folder of results, and field FILE KEY reading one number from a
# --stats-json file (pretty-printed: one key per line).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[1]}")/.."
# TRACER=path/to/tracer measures another build (an older commit's) and builds nothing.
if [[ -z ${TRACER:-} ]]; then
  cmake --preset release >/dev/null
  cmake --build --preset release >/dev/null
fi
T=${TRACER:-build/release/tracer}
O=docs/bench
mkdir -p "$O"
field() { sed -n "s/^ *\"$2\": \([-0-9.e+]*\),\{0,1\}$/\1/p" "$1" | head -1; }
# path_scene_flags SCENE: the tracer flags of a path-traced benchmark scene (cornell-original,
# cornell-water, sponza-sky). The Cornell boxes are lit by their own lamp (as their files define
# them, and as the issue compares them with Cycles) and seen from their view's camera. The view's
# point light is the AO study's: 8-9 cm under the lamp, whose diffuse underside it lights so
# brightly that the lamp becomes a tiny, very bright reflector only BSDF sampling finds; fireflies
# from it set a floor under the error of any sampler (RMSE ~0.025 at 1024 spp). Sponza is lit by a
# white sky alone.
path_scene_flags() {
  local shared=${SHARED:-../shared}
  case $1 in
    cornell-original | cornell-water)
      awk -F'\t' -v v="$1" -v s="$shared/scenes" '$1 == v { print s "/" $2, "--eye", $3, "--look", $4, "--up", $5, "--fov", $6 }' \
        "$shared/scenes/views.tsv" ;;
    sponza-sky) echo --view sponza --env 1,1,1 --no-scene-lights ;;
    *) echo "unknown scene $1" >&2; return 2 ;;
  esac
}
# sponza_without_bumps DIR SHARED: a copy of Sponza's folder in DIR/sponza (links to its files)
# whose MTL has no bump maps, as the benchmarks beside Cycles render it (benchmarks-cycles.sh says
# why); prints the OBJ's path.
sponza_without_bumps() {
  mkdir -p "$1/sponza"
  ln -sf "$2/scenes/sponza/"* "$1/sponza/"
  rm "$1/sponza/sponza.mtl"
  grep -v -E '^\s*(map_bump|bump)\s' "$2/scenes/sponza/sponza.mtl" >"$1/sponza/sponza.mtl"
  echo "$1/sponza/sponza.obj"
}
# seconds_to_rmse TARGET...: from rows "label seconds - rmse" on stdin (renders in order of falling
# error), the seconds to reach each target RMSE, interpolated in log-log between the two renders
# that bracket it; "<s" when the first render is already below, "-" when none reaches it.
seconds_to_rmse() {
  awk -v targets="$*" '{ s[NR] = $2; e[NR] = $4; n = NR }
    END {
      m = split(targets, target, " ")
      for (t = 1; t <= m; ++t) {
        x = target[t]; out = "-"
        if (e[1] <= x) out = sprintf("<%.2f", s[1])
        else for (i = 1; i < n; ++i) if (e[i] > x && e[i + 1] <= x) {
          f = log(e[i] / x) / log(e[i] / e[i + 1])
          out = sprintf("%.2f", exp(log(s[i]) + f * (log(s[i + 1]) - log(s[i]))))
        }
        printf "%s%s", (t > 1 ? " " : ""), out
      }
      print ""
    }'
}
