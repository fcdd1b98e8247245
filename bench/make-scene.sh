#!/usr/bin/env bash
# Writes a generated OBJ scene of about TRIANGLES triangles for the scaling benchmark, and a
# views file (views.tsv format) naming it with its camera and light. The layout never changes:
# a 20×20 grid of UV spheres (radii from 0.25 to 0.45 by position) standing on a floor; only the
# spheres' tessellation grows with TRIANGLES, so times at different sizes compare the same image.
#   bench/make-scene.sh 5000000 /tmp/gen-5m.obj /tmp/gen-5m.tsv
set -euo pipefail
if [[ $# -ne 3 || ! $1 =~ ^[0-9]+$ || $1 -lt 10000 ]]; then
  echo "usage: $0 TRIANGLES(>=10000) OUT.obj OUT-views.tsv" >&2
  exit 2
fi
triangles=$1 obj=$2 views=$3
grid=20
# Per sphere 4·r·(r−1) triangles for r rings and 2r segments (r rounded up: at least TRIANGLES);
# the floor adds 2.
rings=$(awk -v n="$triangles" -v g="$grid" 'BEGIN { t = (n - 2) / (g * g); r = (1 + sqrt(1 + t)) / 2; r = (r == int(r)) ? r : int(r) + 1; if (r < 3) r = 3; print r }')
awk -v grid="$grid" -v rings="$rings" 'BEGIN {
  pi = atan2(0, -1); segs = 2 * rings
  printf "# tracer bench/make-scene.sh: %dx%d spheres, %d rings x %d segments each\n", grid, grid, rings, segs
  print "v -2 0 -2"; print "v 22 0 -2"; print "v 22 0 22"; print "v -2 0 22"
  print "f 1 3 2"; print "f 1 4 3"
  base = 4
  for (gx = 0; gx < grid; gx++) for (gz = 0; gz < grid; gz++) {
    r = 0.25 + 0.2 * ((gx * 7 + gz * 13) % 11) / 10
    cx = gx + 0.5; cz = gz + 0.5; cy = r
    printf "v %.6f %.6f %.6f\n", cx, cy + r, cz
    for (i = 1; i < rings; i++) {
      th = pi * i / rings; y = cy + r * cos(th); s = r * sin(th)
      for (j = 0; j < segs; j++) { ph = 2 * pi * j / segs; printf "v %.6f %.6f %.6f\n", cx + s * cos(ph), y, cz + s * sin(ph) }
    }
    printf "v %.6f %.6f %.6f\n", cx, cy - r, cz
    top = base + 1; first = base + 2; bottom = first + (rings - 1) * segs
    for (j = 0; j < segs; j++) printf "f %d %d %d\n", top, first + (j + 1) % segs, first + j
    for (i = 0; i < rings - 2; i++) for (j = 0; j < segs; j++) {
      a = first + i * segs + j; b = first + i * segs + (j + 1) % segs; c = a + segs; d = b + segs
      printf "f %d %d %d\nf %d %d %d\n", a, b, d, a, d, c
    }
    last = first + (rings - 2) * segs
    for (j = 0; j < segs; j++) printf "f %d %d %d\n", bottom, last + j, last + (j + 1) % segs
    base = bottom
  }
}' > "$obj"
name=$(basename "$obj" .obj)
printf 'scene\tobj\teye\tlook\tup\tfov\tlight\tnote\n%s\t%s\t-3,6,-3\t10,0,10\t0,1,0\t60\t10,15,10\tgenerated: %d spheres of %d rings\n' \
  "$name" "$(realpath "$obj")" $((grid * grid)) "$rings" > "$views"
echo "$obj: $(grep -c '^f ' "$obj") triangles; view '$name' in $views"
