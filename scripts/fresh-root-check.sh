#!/usr/bin/env bash
# Checks the README's quick start where it is promised: on a freshly bootstrapped Debian 12 root
# (debootstrap's minbase: no g++, no cmake, no node), a clean clone of this repository's HEAD
# runs `scripts/setup.sh` then `scripts/test.sh`, with ../shared beside it (bind-mounted
# read-only). Needs root, debootstrap and Debian's archive; about 45 minutes on 2 cores, so it is
# a nightly check, not CI's.
#   scripts/fresh-root-check.sh            bootstrap into a temporary directory, removed after
#   ROOT=/var/tmp/r KEEP=1 scripts/...     bootstrap there and keep it (to look inside)
# Prints each command's last lines and exits with the first failure's status.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)
shared=$(cd "${SHARED:-../shared}" && pwd)
mirror=${MIRROR:-http://deb.debian.org/debian}
[[ $(id -u) -eq 0 ]] || { echo "fresh-root-check: needs root (debootstrap, chroot, mounts)" >&2; exit 2; }
command -v debootstrap >/dev/null || { echo "fresh-root-check: apt-get install debootstrap" >&2; exit 2; }
root=${ROOT:-$(mktemp -d /var/tmp/tracer-root.XXXXXX)}
log=$root.log

mounts=()
cleanup() {
  for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do umount -l "${mounts[i]}" 2>/dev/null || true; done
  [[ -n "${KEEP:-}" ]] || rm -rf "$root"
}
trap cleanup EXIT
bind() {  # bind SOURCE TARGET [ro]
  mkdir -p "$2"
  mount --bind "$1" "$2"
  mounts+=("$2")
  [[ "${3:-}" == ro ]] && mount -o remount,bind,ro "$2"
  return 0
}

step() {  # step NAME COMMAND...: runs it, its output to the log, and says how it ended
  local start=$SECONDS
  echo "== $1" >>"$log"
  if "${@:2}" >>"$log" 2>&1; then
    echo "fresh-root-check: $1: ok ($((SECONDS - start)) s)"
  else
    local rc=$?
    echo "fresh-root-check: $1: FAILED (exit $rc, $((SECONDS - start)) s); the log's end ($log):" >&2
    tail -30 "$log" >&2
    exit "$rc"
  fi
}

: >"$log"
step "debootstrap bookworm" debootstrap --variant=minbase bookworm "$root" "$mirror"
step "clone" git clone -q "$repo" "$root/work/main"
bind "$shared" "$root/work/shared" ro
bind /proc "$root/proc"
bind /sys "$root/sys"
bind /dev "$root/dev"
mkdir -p "$root/dev/shm" && mount -t tmpfs tmpfs "$root/dev/shm" && mounts+=("$root/dev/shm")
cp /etc/resolv.conf "$root/etc/resolv.conf"
# The machine's own network trust, not the project's: where egress goes through a proxy with its
# own certificate authority (/usr/local/share/ca-certificates), the root trusts it too, and node
# (npm) is pointed at the system's bundle as the host's NODE_EXTRA_CA_CERTS does.
if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
  mkdir -p "$root/usr/local/share/ca-certificates"
  cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/"
fi
extra_ca=${NODE_EXTRA_CA_CERTS:+NODE_EXTRA_CA_CERTS=/etc/ssl/certs/ca-certificates.crt}
in_root() { chroot "$root" env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  $extra_ca bash -c "cd /work/main && $1"; }
step "the root has no g++ or cmake" in_root '! command -v g++ && ! command -v cmake'
step "scripts/setup.sh" in_root scripts/setup.sh
step "render.png written" in_root 'test -s render.png'
if compgen -G "$root/usr/local/share/ca-certificates/*.crt" >/dev/null; then
  step "the machine's certificate authorities" in_root update-ca-certificates
fi
step "scripts/test.sh (CI=true: the browser test may not be skipped)" in_root "CI=true scripts/test.sh"
echo "fresh-root-check: the README's two commands pass on a fresh Debian 12 root (log: $log)"
