#!/usr/bin/env bash
# Every bad input, signal and path case of docs/RELIABILITY.md, run against a tracer binary: the
# exit code, the first line tracer prints on stderr, and what is left in the output directory.
#   tests/reliability.sh TRACER             print the table (Markdown)
#   tests/reliability.sh TRACER --check DOC fail unless every case gives the exit code DOC states
#                                           and DOC's table is exactly what this run printed
set -uo pipefail
tracer=$(realpath "$1")
tracer_mpi=$(dirname "$tracer")/tracer-mpi
mode=${2:-}
doc=${3:+$(realpath "$3")}
shared_scenes=$(realpath "$(dirname "$0")/../../shared/scenes")
work=$(mktemp -d)
chmod 755 "$work"  # the unprivileged case must reach its file
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1

# The inputs are written first, then ok.obj is touched: files newer than it are what a case left
# behind, and are removed after each case.
# glTF and PLY: one triangle, its positions then uint16 indices, in a data: URI or a file.
printf '\0\0\0\0\0\0\0\0\0\0\0\0\0\0\200\077\0\0\0\0\0\0\0\0\0\0\0\0\0\0\200\077\0\0\0\0\0\0\001\0\002\0\0\0' > tri.bin
gltf() {  # NODES INDEX-COUNT BUFFER-URI
  printf '{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":%s,"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"buffers":[{"uri":"%s","byteLength":44}],"bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":8}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5123,"count":%s,"type":"SCALAR"}]}\n' "$1" "$3" "$2"
}
data="data:application/octet-stream;base64,$(base64 -w0 tri.bin)"
gltf '[{"mesh":0}]' 3 "$data" > tri.gltf
# The sixth round: leniencies said, and coincident placements placed once.
gltf '[{"mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1],"translation":[1,0,0]}]' 3 "$data" > both.gltf
nodes='[{"children":[1,1]}'
for i in $(seq 1 19); do nodes+=",{\"children\":[$((i + 1)),$((i + 1))]}"; done
gltf "$nodes"',{"mesh":0}]' 3 "$data" > coincide.gltf
# Materials and lights (#64): a spot whose cones are out of order.
gltf '[{"mesh":0,"children":[1]},{"extensions":{"KHR_lights_punctual":{"light":0}}}]' 3 "$data" |
  sed 's/^{/{"extensionsUsed":["KHR_lights_punctual"],"extensions":{"KHR_lights_punctual":{"lights":[{"type":"spot","spot":{"innerConeAngle":0.6,"outerConeAngle":0.5}}]}},/' > spot.gltf
gltf '[{"mesh":0}]' 1000000000 "$data" > count.gltf
gltf '[{"mesh":0,"children":[1]},{"children":[0]}]' 3 "$data" > cycle.gltf
nodes='[{"mesh":0,"children":[1,1]}'
for i in $(seq 1 39); do nodes+=",{\"mesh\":0,\"children\":[$((i + 1)),$((i + 1))]}"; done
gltf "$nodes"',{"mesh":0}]' 3 "$data" > expand.gltf
mkdir gltfdir && mv tri.bin secret.bin
gltf '[{"mesh":0}]' 3 "../secret.bin" > gltfdir/escape.gltf
printf 'glTF\002\000\000\000\377\377\000\000\040\000\000\000JSON{"asset":' > cut.glb
# The fifth round: what tinygltf read as absent, nesting, memory, URIs it called missing.
deep=$(printf '%.0s[' $(seq 20000))$(printf '%.0s]' $(seq 20000))
gltf '[{"mesh":0}]' 3 "$data" | sed "s/^{/{\"extras\":$deep,/" > deep.gltf
gltf '[{"mesh":0}]' 3 "$data" | sed 's/"bufferView":0,/"bufferView":0,"byteOffset":-12,/' > offset.gltf
gltf '[{"mesh":0}]' 3 "$data" | sed 's/"scene":0/"scene":5/' > scene5.gltf
gltf '[{"mesh":0}]' 3 "$data" | sed 's/"componentType":5126/"componentType":5125/' > uintpos.gltf
gltf '[{"mesh":0}]' 3 "/dev/zero" > devzero.gltf
gltf '[{"mesh":0,"camera":0}]' 3 "$data" | sed 's/^{/{"cameras":[{"type":"perspective","perspective":{"znear":0.1}}],/' > noyfov.gltf
gltf '[{"mesh":0,"camera":0}]' 3 "$data" | sed 's/^{/{"cameras":[{"type":"perspective","perspective":{"yfov":1e-30,"znear":0.1}}],/' > tinyfov.gltf
gltf '[{"mesh":0}]' 3 "$data" | sed 's/"primitives":\[{/"primitives":[{"material":0,/; s/^{/{"materials":[{"emissiveFactor":[1,1,1],"extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":1e38}}}],/' > bright.gltf
nodes='[{"children":[1,1]}'
for i in $(seq 1 23); do nodes+=",{\"children\":[$((i + 1)),$((i + 1))]}"; done
gltf "$nodes"',{"mesh":0}]' 3 "$data" > inst24.gltf
# Instances kept as instances (a mesh placed more than once): 2^16 of one triangle, one of zero
# scale, one past float's range, one of a mesh that does not exist.
nodes='[{"children":[1,1]}'
for i in $(seq 1 15); do nodes+=",{\"children\":[$((i + 1)),$((i + 1))]}"; done
gltf "$nodes"',{"mesh":0,"translation":[0.1,0,0]}]' 3 "$data" > inst16.gltf
gltf '[{"mesh":0,"children":[1]},{"mesh":0,"scale":[0,0,0]}]' 3 "$data" > zeroscale.gltf
gltf '[{"mesh":0,"scale":[1e300,1,1],"children":[1]},{"mesh":0,"scale":[1e300,1,1]}]' 3 "$data" > infscale.gltf
gltf '[{"mesh":0,"children":[1]},{"mesh":7}]' 3 "$data" > nomesh.gltf
ln -s "$shared_scenes" shared-scenes  # ../shared/scenes, the same name on every machine
printf 'glTF\001\000\000\000\024\000\000\000\000\000\000\000JSON' > v1.glb
: > empty.gltf
: > empty.ply
cp ok.obj ok.stl 2>/dev/null || printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > ok.stl
ply='ply\nformat %s 1.0\nelement vertex %s\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n'
printf "$ply"'0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' ascii 3 > tri.ply
printf 'v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 1 1 2\nf 3 3 3\n' > degen.obj
printf "$ply"'0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' ascii 4000000000 > count.ply
printf "$ply"'0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n' ascii 3 > range.ply
printf "$ply"'0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n' ascii 3 > extra.ply
printf 'ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float x\nend_header\n0 0\n' > twice.ply
{ printf "$ply" binary_little_endian 3; head -c 36 /dev/zero; printf '\003\0\0\0'; } > cut.ply
{ printf "${ply/face 1/face 2000000}" ascii 3; printf '0 0 0\n1 0 0\n0 1 0\n'; yes '3 0 1 2' | head -n 2000000; } > faces2m.ply
printf 'mtllib dark.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nv 100 100 100\nv 101 100 100\nv 100 101 100\nf 1 2 3\nusemtl lamp\nf 4 6 5\n' > dark.obj
printf 'newmtl lamp\nKe 10 10 10\n' > dark.mtl
printf 'mtllib grey.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl  Lamp\nf 1 2 3\n' > grey.obj
printf 'newmtl  Lamp\nKd 0.5\nKe 1\n' > grey.mtl
printf 'mtllib kdnan.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl a\nf 1 2 3\n' > kdnan.obj
printf 'newmtl a\nKd nan 0 0\n' > kdnan.mtl
printf 'mtllib real.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl a\nf 1 2 3\n' > real.obj
printf 'newmtl a\nTr 0  0\nTr 0  illum 2\nKa 0.0000 0.0000 0.0000c\nKd 0.5 0.5 0.5\nmap_Kd -o 0.5 0.5 -s 2 2 none.png\n' > real.mtl
printf 'mtllib notmtl.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n' > notmtl.obj
cp notmtl.obj notmtl.mtl
printf 'v -1e13 -1e13 0\nv 1e13 -1e13 0\nv 0 1e13 0\nf 1 2 3\n' > huge.obj
printf 'mtllib zero.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > zero.obj
ln -s /dev/zero zero.mtl
printf 'mtllib never.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > fifomtl.obj
mkfifo never.mtl
printf 'mtllib bomb.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl a\nf 1 2 3\n' > bomb.obj
printf 'newmtl a\nmap_Kd bomb.png\n' > bomb.mtl
# A PNG header claiming 16384 x 16384 texels (IHDR and its CRC), and nothing more.
printf '\211PNG\r\n\032\n\000\000\000\rIHDR\000\000\100\000\000\000\100\000\010\002\000\000\000\046\252\207\323' > bomb.png
# Environment maps: a header claiming the largest map with 40 bytes behind it, and a whole
# 16256 x 8192 map (every scanline 128 runs of 127 texels a channel: 8 MB) to interrupt.
{ printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 16384\n'; head -c 40 /dev/zero; } > claim.hdr
{ printf '\002\002\077\200'; for i in $(seq 512); do printf '\377\200'; done; } > rows.bin
for i in $(seq 13); do cat rows.bin rows.bin > rows2.bin && mv rows2.bin rows.bin; done
{ printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 16256\n'; cat rows.bin; } > big.hdr && rm rows.bin
"$tracer" render -q --integrator ao --ao 0 --width 2048 --height 1024 -o whole.exr && head -c 400 whole.exr > cut.exr && rm whole.exr
mkdir envA envB
"$tracer" render -q --integrator ao --ao 0 --width 8 --height 4 -o envA/sky.exr
"$tracer" render -q --integrator ao --ao 0 --width 16 --height 8 -o envB/sky.exr
# png16 W H: a 16-bit RGB PNG of W x H black texels on stdout (zlib by gzip: all-zero rows, so
# the Adler-32 is (len mod 65521) << 16 | 1; the chunk CRCs are gzip's CRC-32 of each chunk).
png16() {
  local w=$1 h=$2 tmp
  tmp=$(mktemp -d)
  be32() { printf "\\$(printf '%03o' $(( ($1 >> 24) & 255 )))\\$(printf '%03o' $(( ($1 >> 16) & 255 )))\\$(printf '%03o' $(( ($1 >> 8) & 255 )))\\$(printf '%03o' $(( $1 & 255 )))"; }
  crc_of() { gzip -c < "$1" | tail -c 8 | head -c 4 | od -An -tu4 | tr -d ' '; }
  chunk() {  # type data-file
    printf '%s' "$1" > "$tmp/c"; cat "$2" >> "$tmp/c"
    be32 "$(stat -c %s "$2")"; cat "$tmp/c"; be32 "$(crc_of "$tmp/c")"
  }
  { be32 "$w"; be32 "$h"; printf '\020\002\000\000\000'; } > "$tmp/ihdr"
  local raw=$(( (w * 6 + 1) * h ))
  { printf '\170\234'; head -c "$raw" /dev/zero | gzip -9 -n | tail -c +11 | head -c -8; be32 $(( ((raw % 65521) << 16) | 1 )); } > "$tmp/idat"
  : > "$tmp/iend"
  printf '\211PNG\r\n\032\n'; chunk IHDR "$tmp/ihdr"; chunk IDAT "$tmp/idat"; chunk IEND "$tmp/iend"
  rm -rf "$tmp"
}
# Twelve 16-bit 4096^2 textures (stb_image decodes each through ~400 MB of buffers).
png16 4096 4096 > t0.png
{ printf 'mtllib many.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n'; for i in $(seq 0 11); do printf 'usemtl m%d\nf 1/1 2/2 3/3\n' "$i"; done; } > many.obj
for i in $(seq 0 11); do [[ $i -gt 0 ]] && cp t0.png "t$i.png"; printf 'newmtl m%d\nmap_Kd t%d.png\n' "$i" "$i"; done > many.mtl
mkdir viewsdir
printf 'v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n' > viewsdir/tri.obj
printf 'scene\tobj\teye\tlook\tup\tfov\tlight\ntri\ttri.obj\t0,0,3\t0,0\n' > viewsdir/views.tsv
printf 'scene\tobj\teye\tlook\tup\tfov\tlight\ntri\tok.obj\t0,0,3\t0,0,0\t0,1,0\t45\t0,0,2\n' > tri-views.tsv
mkfifo out-fifo.png
ln -s target.png link.png
printf 'mtllib tex.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 2/2 3/3\n' > tex.obj
printf 'newmtl a\nmap_Kd Missing.PNG\nnewmtl b\nmap_Kd missing.png\n' > tex.mtl
printf 'v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n' > ok.obj
printf '# c\rv 1e39 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -3 -2 -1\n' > cr.obj
printf 'v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n' > nan.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n' > range.obj
printf '# nothing\n' > empty.obj
printf 'v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n' > same.obj
printf 'v 0 0 0\nv 1e-30 0 0\nv 0 1e-30 0\nf 1 2 3\n' > tiny.obj
printf 'mtllib ihdr.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl a\nf 1 2 3\n' > ihdr.obj
printf 'newmtl a\nmap_Kd ihdr.png\n' > ihdr.mtl
printf '\211PNG\r\n\032\n\000\000\000\rIHDR\000\000\000\010\000\000\000\010\010\002\000\000\000\113\155\051\336' > ihdr.png
printf 'v 0 0 0\nv 1\001 0 0\nv 0 1 0\nf 1 2 3\n' > control.obj
printf '\357\273\277v 0 0 0\nv +1 0 1e-50\nv 0 1 0\nf 1 2 3\n' > bom.obj
{ printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n'; for i in $(seq 20000); do printf 'usemtl undefined%d\nf 1 2 3\n' "$i"; done; } > materials.obj
{
  for i in $(seq 0 1999); do echo "v $((i % 50)) $((i / 50)) 0"; done
  for i in $(seq 1 1949); do echo "f $i $((i + 1)) $((i + 50))"; done
} > slow.obj
ln -s loop-b loop-a
ln -s loop-a loop-b
mkdir scenes.d
cp ok.obj locked.obj
chmod 000 locked.obj
mkfifo fifo.obj
mkfifo silent.obj
mkfifo nowriter.obj

touch ok.obj  # after every input: an input in a later clock tick than ok.obj would be removed
inputs=$(ls)
as_user=()
[[ $(id -u) -eq 0 ]] && as_user=(setpriv --reuid=65534 --regid=65534 --clear-groups)
MPIRUN="mpirun --allow-run-as-root --oversubscribe"
# Runs an mpirun command line, stops rank $1 with SIGSTOP once it renders, and once rank 0 has
# written m.png continues and kills it; exits with mpirun's code.
# stall_rank RANK [--at-start] COMMAND...: runs COMMAND (an mpirun job) and stops rank RANK with
# SIGSTOP once it renders (it has used a quarter second of CPU: MPI's start-up waits in usleep;
# at once with --at-start: in MPI's start-up), then waits for the job to end (rank 0 writes the
# image and ends the job, or a rank's deadline ends it) and kills the stopped rank as soon as the
# image appears (continued by mpirun's abort, it would report rank 0's silence as a second error).
stall_rank() {
  local rank=$1 victim="" pid at_start=0
  shift
  [[ $1 == --at-start ]] && at_start=1 && shift
  "$@" &
  local job=$!
  for _ in $(seq 2000); do
    for pid in $(pgrep -f "tracer-mpi render"); do
      tr '\0' '\n' < "/proc/$pid/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$rank" && victim=$pid
    done
    [[ -n $victim ]] && break
    sleep 0.01
  done
  if ((!at_start)); then
    sleep 1
    local quarter=$(($(getconf CLK_TCK) / 4))
    for _ in $(seq 600); do
      (($(awk '{print $14 + $15}' "/proc/$victim/stat" 2>/dev/null || echo "$quarter") >= quarter)) && break
      sleep 0.1
    done
  fi
  kill -STOP "$victim"
  for _ in $(seq 600); do
    kill -0 "$job" 2>/dev/null || break
    [[ -f m.png ]] && break
    sleep 0.1
  done
  kill -KILL "$victim" 2>/dev/null
  kill -CONT "$victim" 2>/dev/null
  # Bounded: Open MPI's mpirun has been seen to deadlock on a loaded machine, its ranks ended and
  # unreaped (a futex wait, 18 minutes before it was killed); the case then ends, said.
  for _ in $(seq 600); do
    kill -0 "$job" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$job" 2>/dev/null; then
    echo "reliability.sh: mpirun still running 60 s after its job ended; killed" >&2
    pkill -KILL -P "$job" 2>/dev/null
    kill -KILL "$job" 2>/dev/null
  fi
  wait "$job"
}
export -f stall_rank
# start_viewer: `tracer view ok.obj` on a free port in the background; sets viewer (its pid),
# port and token. stop_viewer ends it.
start_viewer() {
  viewer_out=$(mktemp)
  "$TRACER_BIN" view ok.obj --port 0 -q > "$viewer_out" 2>/dev/null &
  viewer=$!
  for _ in $(seq 200); do grep -q 'token=' "$viewer_out" && break; sleep 0.05; done
  port=$(sed -E 's|.*:([0-9]+)/.*|\1|' "$viewer_out")
  token=$(sed -E 's|.*token=([0-9a-f]+).*|\1|' "$viewer_out")
}
stop_viewer() {
  kill -INT "$viewer"
  wait "$viewer" 2>/dev/null
  rm -f "$viewer_out"
}
export -f start_viewer stop_viewer
# view_request REQUEST: starts `tracer view ok.obj` on a free port, sends REQUEST (PORT and TOKEN
# replaced by the viewer's) over a raw connection, and writes the answer's status line and its
# error message to stderr (the table's column); the viewer is then stopped.
view_request() {
  local viewer viewer_out port token
  start_viewer
  local request=${1//PORT/$port}
  request=${request//TOKEN/$token}
  exec 3<>"/dev/tcp/127.0.0.1/$port"
  printf '%b' "$request" >&3
  local answer
  answer=$(timeout 5 cat <&3 | tr -d '\r')
  exec 3<&-
  stop_viewer
  echo "$(head -n 1 <<< "$answer"): $(tail -n 1 <<< "$answer")" >&2
}
export -f view_request
# slow_clients: fifty connections to `tracer view` trickling a header line a second (no token),
# then a real request; its status line goes to stderr.
slow_clients() {
  local viewer viewer_out port token
  start_viewer
  local slow=()
  for _ in $(seq 50); do
    (exec 3<>"/dev/tcp/127.0.0.1/$port" && printf 'GET /state HTTP/1.1\r\n' >&3 &&
      for _ in $(seq 8); do printf 'X-Slow: 1\r\n' >&3 || break; sleep 1; done) 2>/dev/null &
    slow+=($!)
  done
  sleep 1.5
  exec 3<>"/dev/tcp/127.0.0.1/$port"
  printf 'GET /state?token=%s HTTP/1.1\r\nHost: 127.0.0.1:%s\r\nConnection: close\r\n\r\n' "$token" "$port" >&3
  local answer
  answer=$(timeout 5 head -n 1 <&3 | tr -d '\r')
  exec 3<&-
  kill "${slow[@]}" 2>/dev/null
  stop_viewer
  echo "${answer:-no answer within 5 s}" >&2
}
export -f slow_clients
# peak_below JSON MIB: fails, saying so, if the --stats-json file's peak_rss_mib is MIB or more.
peak_below() {
  local peak
  peak=$(sed -nE 's/.*"peak_rss_mib": ([0-9.]+).*/\1/p' "$1")
  awk -v p="$peak" -v m="$2" 'BEGIN { exit !(p < m) }' || { echo "peak memory $peak MiB, not below $2" >&2; return 1; }
}
export -f peak_below
export TRACER_BIN=$tracer
SLOW="render slow.obj -q --accel brute --width 2048 --height 2048 -o out.png"
PATH_RENDER="render ok.obj -q --integrator path --spp 1000000 --width 128 --height 128 -o out.png"

# case | command (run by bash in the work directory) | expected exit code
cases=(
  "missing scene|tracer render nowhere.obj -q|1"
  "scene is a directory|tracer render scenes.d -q|1"
  "scene is a symlink loop|tracer render loop-a -q|1"
  "scene not readable (as an unprivileged user)|USER tracer render locked.obj -q -o /tmp/x.png|1"
  "lone CR ends a comment, next line has 1e39|tracer render cr.obj -q --accel embree|1"
  "NaN coordinate|tracer render nan.obj -q|1"
  "face index out of range|tracer render range.obj -q|1"
  "no triangles|tracer render empty.obj -q|1"
  "glTF: one triangle|tracer render tri.gltf -q --width 32 --height 32 -o g.png|0"
  "glTF: an accessor's count past its buffer|tracer render count.gltf -q|1"
  "glTF: a buffer URI that leaves the scene's folder|tracer render gltfdir/escape.gltf -q|1"
  "glTF: nodes in a cycle|tracer render cycle.gltf -q|1"
  "glTF: 2^40 instances of a triangle in 1 KB|tracer render expand.gltf -q --max-memory-mib 1024|1"
  "glTF: a .glb cut short|tracer render cut.glb -q|1"
  "glTF: --camera of a scene without cameras|tracer render tri.gltf --camera 0 -q|2"
  "PLY: one triangle|tracer render tri.ply -q --width 32 --height 32 -o p.png|0"
  "PLY: a vertex count the file cannot hold|tracer render count.ply -q|1"
  "PLY: a face index out of range|tracer render range.ply -q|1"
  "PLY: binary data cut short|tracer render cut.ply -q|1"
  "glTF: JSON nested 20,000 levels deep in 40 KB|tracer render deep.gltf -q|1"
  "glTF: an accessor byteOffset of -12|tracer render offset.gltf -q|1"
  "glTF: a scene index that names no scene|tracer render scene5.gltf -q|1"
  "glTF: UNSIGNED_INT positions|tracer render uintpos.gltf -q|1"
  "glTF: a buffer URI /dev/zero|tracer render devzero.gltf -q|1"
  "glTF: a perspective camera without yfov|tracer render noyfov.gltf -q|1"
  "glTF: a yfov of 1e-30 (below --fov's range)|tracer render tinyfov.gltf -q|1"
  "glTF: emissive strength 1e38 (above MTL's Ke limit)|tracer render bright.gltf -q|1"
  "glTF: a GLB of version 1|tracer render v1.glb -q|1"
  "glTF: an empty file|tracer render empty.gltf -q|1"
  "glTF: 2^24 instances past --max-memory-mib 1024|tracer render inst24.gltf -q --max-memory-mib 1024|1"
  "glTF: tracer info of 2^24 instances (each node counted once)|tracer info inst24.gltf > /dev/null|0"
  "glTF: 2^16 instances of a triangle (a two-level tree)|tracer render inst16.gltf -q --width 32 --height 32 -o i.png|0"
  "glTF: an instance of zero scale beside one of scale 1|tracer render zeroscale.gltf --width 16 --height 16 -o z.png|0"
  "glTF: instances whose scales multiply past float's range|tracer render infscale.gltf -q|1"
  "glTF: an instance of a mesh that does not exist|tracer render nomesh.gltf -q|1"
  "PLY: an extra value on a row|tracer render extra.ply -q|1"
  "PLY: a property declared twice|tracer render twice.ply -q|1"
  "PLY: an empty file|tracer render empty.ply -q|1"
  "a scene of an unknown extension (.stl)|tracer render ok.stl -q|1"
  "16384 x 16384 with three AOVs, past the memory limit|tracer render --width 16384 --height 16384 --aov albedo,normal,samples --max-memory-mib 16384 -q -o big.exr|2"
  "--denoise with the ao integrator|tracer render --denoise --integrator ao -q|2"
  "--aov noisy without --denoise|tracer render --aov noisy -q -o n.exr|2"
  "8192 x 8192 denoised, past the memory limit|tracer render --width 8192 --height 8192 --denoise --max-memory-mib 16384 -q|2"
  "Ctrl-C while denoising|timeout --foreground --preserve-status -s INT 3 tracer render --width 1536 --height 1536 --spp 1 --denoise -q -o d.png|130"
  "a scene and its accelerator past --max-memory-mib|tracer render --builtin-spheres 200000 --max-memory-mib 48 --width 8 --height 8 -q|1"
  "OBJ: the Bunny past --max-memory-mib 8, refused once parsed|tracer render shared-scenes/bunny/bunny.obj --max-memory-mib 8 --width 8 --height 8 -q|1"
  "PLY: 2M faces past --max-memory-mib 64, refused at its header|tracer render faces2m.ply --max-memory-mib 64 --width 8 --height 8 -q|1"
  "--max-memory-mib 0|tracer render --max-memory-mib 0 -q|2"
  "--aperture 0.1 --focus-distance 1e-30|tracer render --aperture 0.1 --focus-distance 1e-30 -q|2"
  "--build-quality HIGH (names are exact)|tracer render --build-quality HIGH -q|2"
  "bench --build-quality high|tracer bench --size 8x8 --runs 1 --best 1 --variants bvh8 --scenes ok.obj --build-quality high > /dev/null|0"
  "bench on zero-area triangles only, every kind of accelerator|tracer bench --size 8x8 --runs 1 --best 1 --variants seq,bvh,simd-brute,sah,bvh8,best,bvh8-high,embree,embree-packets,embree-high --scenes degen.obj > /dev/null|0"
  "tracer view: SIGINT 50 ms after start, in the background|tracer view ok.obj --port 0 -q > /dev/null & sleep 0.05 ; kill -INT \$! ; wait \$!|130"
  "Ctrl-C while Sponza loads and builds at high quality|timeout --foreground --preserve-status -s INT 0.5 tracer render shared-scenes/sponza/sponza.obj --build-quality high -q|130"
  "all vertices coincide, no camera flags|tracer render same.obj -q|1"
  "control character in a number|tracer render control.obj -q|1"
  "UTF-8 byte-order mark, +1, 1e-50|tracer render bom.obj -q --width 32 --height 32|0"
  "20,000 undefined material names|tracer render materials.obj --width 32 --height 32 -o m.png|0"
  "scene from standard input (-)|tracer render - -q --width 32 --height 32 -o stdin.png < ok.obj|0"
  "scene from a pipe|tracer render <(cat ok.obj) -q --width 32 --height 32 -o pipe.png|0"
  "scene from a FIFO|(cat ok.obj > fifo.obj &) ; tracer render fifo.obj -q --width 32 --height 32 -o fifo.png|0"
  "a scene of extent 1e-30, no camera flags|tracer render tiny.obj -q|1"
  "--max-input-mib 99999999999999999999|tracer render --max-input-mib 99999999999999999999 -q|2"
  "--stats-json ''|tracer render -q --stats-json ''|2"
  "--stats-json - (standard output)|tracer render -q --width 8 --height 8 -o s.png --stats-json - > /dev/null|0"
  "bench --json and --plot one file|tracer bench --size 8x8 --runs 1 --best 1 --variants bvh --scenes ok.obj --json b.json --plot ./b.json|2"
  "bench --json is a scene's MTL|tracer bench --size 8x8 --runs 1 --best 1 --variants bvh --scenes tex.obj --json tex.mtl|2"
  "camera beyond +-1e18|tracer render --eye 0,1,1e19 --look 0,1,0 -q|2"
  "--stats-json is the scene|tracer render ok.obj -q --stats-json ok.obj|2"
  "--stats-json is the -o image|tracer render ok.obj -q -o a.png --stats-json ./a.png|2"
  "-o in a missing directory|tracer render ok.obj -q -o no/such/dir.png|1"
  "-o with an unknown extension|tracer render ok.obj -q -o out.jpg|2"
  "--threads 0|tracer render --threads 0 -q|2"
  "one allowed core (taskset -c 0), default threads|taskset -c 0 tracer render -q --width 32 --height 32 -o t.png|0"
  "--threads 64 on a smaller machine|tracer render --threads 64 -q --width 32 --height 32 -o t.png|0"
  "--spp 0|tracer render --integrator path --spp 0 -q|2"
  "tracer view: a port out of range|tracer view ok.obj --port 70000 -q|2"
  "tracer view: --listen ''|tracer view ok.obj --listen '' -q|2"
  "tracer view: --listen 0.0.0.0 (beyond this machine), then Ctrl-C|timeout --foreground --preserve-status -s INT 2 tracer view ok.obj --listen 0.0.0.0 --port 0 -q > /dev/null|130"
  "tracer view: the port already served by another viewer|(timeout -s INT 3 tracer view ok.obj --port 18734 -q > /dev/null 2>&1 &) ; sleep 1.5 ; tracer view ok.obj --port 18734 -q|2"
  "tracer view: a chunked POST to /control (the 4 KiB limit held)|view_request 'POST /control?token=TOKEN HTTP/1.1\\r\\nHost: 127.0.0.1:PORT\\r\\nContent-Type: application/json\\r\\nTransfer-Encoding: chunked\\r\\n\\r\\n2\\r\\n{}\\r\\n0\\r\\n\\r\\n'|0"
  "tracer view: a POST without Content-Length|view_request 'POST /control?token=TOKEN HTTP/1.1\\r\\nHost: 127.0.0.1:PORT\\r\\nContent-Type: application/json\\r\\n\\r\\n'|0"
  "tracer view: Host evil.example (DNS rebinding), with the token|view_request 'GET /state?token=TOKEN HTTP/1.1\\r\\nHost: evil.example:PORT\\r\\n\\r\\n'|0"
  "tracer view: the token twice, the second wrong|view_request 'GET /state?token=TOKEN&token=bad HTTP/1.1\\r\\nHost: 127.0.0.1:PORT\\r\\n\\r\\n'|0"
  "tracer view: fifty connections trickling header lines, then a real request|slow_clients|0"
  "tracer view: a render flag it has no use for|tracer view ok.obj --frames 3 -q|2"
  "tracer view: Ctrl-C (SIGINT) while serving|timeout --foreground --preserve-status -s INT 2 tracer view ok.obj --port 0 -q|130"
  "--spp with --integrator ao (anti-aliasing)|tracer render --integrator ao --spp 4 -q --width 8 --height 8 -o a.png|0"
  "--env with a negative component|tracer render --integrator path --env 1,-1,1 -q|2"
  "--checkpoint 0|tracer render --integrator path --checkpoint 0 -q|2"
  "two materials name a missing texture|tracer render tex.obj --width 32 --height 32 -o t.png|0"
  "bench --variants ''|tracer bench --variants ''|2"
  "bench --scenes ,|tracer bench --scenes ,|2"
  "bench --size 32x32x99junk|tracer bench --size 32x32x99junk|2"
  "bench --size 99999999999x2|tracer bench --size 99999999999x2|2"
  "bench --threads 0|tracer bench --threads 0|2"
  "Ctrl-C (SIGINT) while rendering|timeout --foreground --preserve-status -s INT 1 tracer $SLOW|130"
  "Ctrl-C with --save-partial|timeout --foreground --preserve-status -s INT 1 tracer $SLOW --save-partial|130"
  "SIGTERM while rendering|timeout --foreground --preserve-status -s TERM 1 tracer $SLOW|143"
  "SIGHUP while rendering|timeout --foreground --preserve-status -s HUP 1 tracer $SLOW|129"
  "Ctrl-C while the scene is still arriving, --save-partial|(sleep 5 > silent.obj &) ; timeout --foreground --preserve-status -s INT 1 tracer render silent.obj -q --save-partial -o out.png|130"
  "kill -9 while rendering|timeout --foreground --preserve-status -s KILL 1 tracer $SLOW|137"
  "Ctrl-C during a path render (after its first pass)|timeout --foreground --preserve-status -s INT 2 tracer $PATH_RENDER|130"
  "Ctrl-C with --sched async (rows already running stop too)|timeout --foreground --preserve-status -s INT 1 tracer $SLOW --sched async|130"
  "Ctrl-C with one 4096-pixel tile|timeout --foreground --preserve-status -s INT 1 tracer $SLOW --tile 4096|130"
  "SIGINT while opening a FIFO scene with no writer|timeout --foreground --preserve-status -s INT 1 tracer render nowriter.obj -q|130"
  "SIGTERM while opening a FIFO scene with no writer|timeout --foreground --preserve-status -s TERM 1 tracer render nowriter.obj -q|143"
  "SIGHUP while opening a FIFO scene with no writer|timeout --foreground --preserve-status -s HUP 1 tracer render nowriter.obj -q|129"
  "Ctrl-C while an mtllib FIFO has no writer|timeout --foreground --preserve-status -s INT 1 tracer render fifomtl.obj -q|130"
  "mtllib is /dev/zero|tracer render zero.obj -q|1"
  "--stats-json into a device node|tracer render ok.obj -q --width 8 --height 8 -o o.png --stats-json /dev/null|0"
  "--stats-json into a full device|tracer render ok.obj -q --width 8 --height 8 -o o.png --stats-json /dev/full|1"
  "-o into a FIFO|(cat out-fifo.png > /dev/null &) ; tracer render ok.obj -q --width 8 --height 8 -o out-fifo.png|0"
  "-o is a symbolic link: its target is written|tracer render ok.obj -q --width 8 --height 8 -o link.png|0"
  "--stats-json is the scene's MTL|tracer render tex.obj -q --stats-json tex.mtl|2"
  "bench --plot is the scene|tracer bench --size 8x8 --runs 1 --best 1 --variants bvh --scenes ok.obj --plot ok.obj|2"
  "--fov 1e-30 with Embree|tracer render --fov 1e-30 --accel embree -q|2"
  "a triangle beyond +-1e12|tracer render huge.obj -q --integrator ao --ao 0|1"
  "--env-rotation 1e300 with --env-map|tracer render --integrator path --env-map big.hdr --env-rotation 1e300 -q|2"
  "an .hdr header claiming 16384x8192 texels, 40 bytes of pixels|tracer render --integrator path --env-map claim.hdr -q|1"
  "Ctrl-C while a 16256x8192 environment map decodes|timeout --foreground --preserve-status -s INT 1 tracer render --integrator path --env-map big.hdr -q|130"
  "a sky at the radiance limit 1e6 seen directly, into a half EXR|tracer render --integrator path --env 1e6,1e6,1e6 --spp 1 --width 8 --height 8 -o sky.exr|0"
  "--env above the radiance limit (1e6, as Ke and glTF emission)|tracer render --integrator path --env 1e20,1e20,1e20 -q|2"
  "--denoise of a sky at the radiance limit: white, not black|tracer render --integrator path --env 1e6,1e6,1e6 --denoise --spp 4 --width 16 --height 16 -o bright.png|0"
  "--no-scene-lights under path with no other light: black, said|tracer render --integrator path --no-scene-lights --env 0,0,0 --spp 2 --width 8 --height 8 -o dark.png|0"
  "--stats-json naming a frame's expanded name|tracer render ok.obj -q --width 8 --height 8 --frames 2 -o fr.png --stats-json fr-0001.png|2"
  "--light before the scene takes one value|tracer render --light 0,0,2 ok.obj -q --width 8 --height 8 -o l.png|0"
  "a value flag given twice|tracer render --spp 4 --spp 8 -q|2"
  "--min-spp above --spp|tracer render --integrator path --spp 4 --min-spp 8 -q|2"
  "--focus-distance without --aperture|tracer render ok.obj --integrator path --env 1,1,1 --spp 1 --focus-distance 2 --width 8 --height 8 -o f.png|0"
  "--denoise of a 1-pixel-wide image past --max-memory-mib (padded planes counted)|tracer render --width 1 --height 16384 --denoise --max-memory-mib 200 -q|2"
  "glTF node with a matrix and a translation|tracer render both.gltf --integrator ao --width 8 --height 8 -o both.png|0"
  "glTF of 2^20 coincident placements of one mesh|tracer render coincide.gltf --integrator ao --width 8 --height 8 -o co.png|0"
  "glTF spot light whose inner cone is wider than its outer|tracer render spot.gltf -q|1"
  "tracer view sent SIGINT 30 ms after a script starts it in the background|tracer view ok.obj --port 0 -q & sleep 0.03; kill -INT \$!; wait \$!|130"
  "compare: an EXR of 2048x1024 cut after 400 bytes|tracer compare cut.exr cut.exr|1"
  "Kd nan in the MTL|tracer render kdnan.obj -q|1"
  "a real exporter's MTL: Tr 0  0, Tr 0  illum 2, 0.0000c, -o and -s of two values|tracer render real.obj --width 8 --height 8 -o r.png|0"
  "mtllib names a file that is no MTL|tracer render notmtl.obj --width 8 --height 8 -o n.png|0"
  "Kd 0.5 (one value: grey), newmtl with two spaces|tracer render grey.obj -q --width 8 --height 8 -o g.png|0"
  "the only emitter out of view|tracer render dark.obj -q --width 8 --height 8 --spp 2 --eye 0,0,3 --look 0,0,0 -o d.png|0"
  "an empty scene name|tracer render '' -q|2"
  "an unknown --view|tracer render --view unknown --views tri-views.tsv -q|2"
  "--integrator whitted --spp 4|tracer render --integrator whitted --spp 4 -q --width 8 --height 8 -o w.png|0"
  "twelve 16-bit 4096x4096 textures under --max-texture-mib 512: peak memory below 672 MiB|tracer render many.obj --max-texture-mib 512 --threads 2 --integrator ao --width 8 --height 8 -o many.png --stats-json many.json && peak_below many.json 672|0"
  "a texture of only its IHDR chunk|tracer render ihdr.obj --width 8 --height 8 -o i.png|0"
  "a texture claiming 16384x16384 texels|tracer render bomb.obj --width 8 --height 8 -o b.png|0"
  "a bad views.tsv beside the scene|tracer render viewsdir/tri.obj --width 8 --height 8 -o v.png|0"
  "tracer-mpi: one rank refuses a flag (an older binary)|$MPIRUN -np 1 tracer-mpi render -q --width 32 --height 32 -o m.png : -np 1 tracer-mpi render -q --width 32 --height 32 -o m.png --newer-flag|2"
  "tracer-mpi: ranks given different --width|$MPIRUN -np 1 tracer-mpi render -q --width 32 --height 32 -o m.png : -np 1 tracer-mpi render -q --width 64 --height 32 -o m.png|2"
  "tracer-mpi: ranks given different --noise-threshold (rank 0 judges the noise)|$MPIRUN -np 1 tracer-mpi render -q --integrator path --spp 2 --width 16 --height 16 --noise-threshold 0.05 -o m.png : -np 1 tracer-mpi render -q --integrator path --spp 2 --width 16 --height 16 --noise-threshold 0.1 -o m.png|2"
  "tracer-mpi: one rank focuses at 2, the other at the look-at point|$MPIRUN -np 1 tracer-mpi render -q --integrator path --spp 2 --width 16 --height 16 --aperture 0.1 --focus-distance 2 -o m.png : -np 1 tracer-mpi render -q --integrator path --spp 2 --width 16 --height 16 --aperture 0.1 -o m.png|2"
  "tracer-mpi: adaptive sampling and a lens on a glTF scene and a PLY scene|$MPIRUN -np 2 tracer-mpi render tri.gltf -q --integrator path --spp 8 --width 16 --height 16 --noise-threshold 0.05 --aperture 0.05 -o mg.png && $MPIRUN -np 2 tracer-mpi render tri.ply -q --integrator path --spp 8 --width 16 --height 16 --noise-threshold 0.05 -o mp.png|0"
  "tracer-mpi: rank 0 stopped (SIGSTOP) mid-render|stall_rank 0 $MPIRUN -np 2 tracer-mpi render -q --integrator path --spp 4096 --width 96 --height 96 --threads 1 --rank-timeout 1 -o m0.png|1"
  "tracer-mpi: rank 1 stopped (SIGSTOP) in start-up (the job fails: exit 0 here)|! stall_rank 1 --at-start $MPIRUN -np 3 tracer-mpi render -q --integrator ao --width 32 --height 32 --startup-timeout 3 -o m1.png|0"
  "tracer-mpi: one --env-map path, two files (other working directories)|$MPIRUN -np 1 -wdir envA tracer-mpi render -q --integrator path --spp 1 --width 8 --height 8 --env-map sky.exr -o m2.png : -np 1 -wdir envB tracer-mpi render -q --integrator path --spp 1 --width 8 --height 8 --env-map sky.exr -o m2.png|1"
  "tracer-mpi: rank 1 stopped (SIGSTOP) mid-render|stall_rank 1 $MPIRUN -np 2 tracer-mpi render -q --integrator path --spp 1024 --width 96 --height 96 --threads 1 --rank-timeout 1 -o m.png|1"
)

table=$'| case | command | exit | first line on stderr | left in the directory |\n|---|---|---:|---|---|\n'
failures=0
for c in "${cases[@]}"; do
  IFS='|' read -r name cmd expected <<< "$c"
  run=${cmd//tracer-mpi /\"\$tracer_mpi\" }
  run=${run//tracer /\"\$tracer\" }
  run=${run//USER /\"\$\{as_user[@]\}\" }
  stderr=$(tracer=$tracer tracer_mpi=$tracer_mpi bash -c "as_user=(${as_user[*]}); $run" 2>&1 >/dev/null)
  code=$?
  # How many samples a stopped path render finished depends on the machine's speed: shown as N.
  # tracer's own first line (mpirun's banners may come first); the bound tracer-mpi derives from
  # measured tile times is shown as N too.
  # From a here-string, not a pipe: grep -m 1 exits before a long stderr is written, and under
  # pipefail the writer's SIGPIPE would run the fallback as well (two lines).
  first=$(grep -m 1 '^tracer' <<<"$stderr" || head -n 1 <<<"$stderr")
  first=$(printf '%s\n' "$first" | sed -E 's/after [0-9]+ of/after N of/; s/within [0-9]+ s/within N s/; s/rank [0-9]+ of ([0-9]+): start-up/rank N of \1: start-up/')
  [[ -z $first ]] && first="(nothing)"
  left=$(comm -13 <(echo "$inputs") <(ls) | tr '\n' ' ')
  left=${left% }
  [[ -z $left ]] && left="nothing new"
  [[ $left == *.tmp-* ]] && left="$left (a temporary file)"
  shown=${cmd//USER /}
  table+="| $name | \`${shown//|/\\|}\` | $code | ${first//|/\\|} | $left |"$'\n'
  if [[ $code != "$expected" ]]; then
    echo "reliability: '$name' exited $code, expected $expected: $first" >&2
    failures=$((failures + 1))
  fi
  find . -maxdepth 1 -newer ok.obj -type f ! -name '*.obj' -delete
  rm -rf no
done

if [[ $mode == --check ]]; then
  expected_table=$(sed -n '/^| case |/,/^$/p' "$doc")
  if [[ "$expected_table" != "${table%$'\n'}" ]]; then
    echo "reliability: $doc differs from this run (regenerate it with tests/reliability.sh):" >&2
    diff <(echo "$expected_table") <(echo "${table%$'\n'}") >&2
    failures=$((failures + 1))
  fi
  echo "reliability: $(( ${#cases[@]} - failures )) passed, $failures failed"
  exit $((failures > 0))
fi
printf '%s' "$table"
exit $((failures > 0))
