#!/usr/bin/env bash
# CI: README's commands on a truly fresh Debian 12. A minimal root (debootstrap --variant=minbase bookworm, from the
# Debian mirror this machine's apt sources name), a clone of the commit copied in, and the commands of README.md's
# first code block run inside it as root, one after the other, exactly as written there (so README stays true): a
# package that setup-debian.sh forgets to install fails here instead of on a user's machine.
#   bash cmake/ci-fresh-debian.sh [CLONE [WORKDIR [COMMAND...]]]
#     CLONE    a git clone whose checked-out commit is tested (default: this repository); only committed files go in
#     WORKDIR  where the root is built (default: a new temporary folder); removed at the end unless
#              QUATHINGE_FRESH_KEEP=1
#     COMMAND  run in the root after README's commands, in their builds (CI: `bash demos/check_generated.sh`, which
#              checks the generated figures against README's native float build)
# Needs root (debootstrap, chroot, mount; through sudo otherwise) and the network to the Debian mirror. proc, sys, dev
# (+ dev/pts, dev/shm) are mounted into the root and unmounted on exit, whatever happens; processes left running
# inside the root are ended first.
set -euo pipefail
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "ci-fresh-debian: needs root (debootstrap, chroot, mount)" >&2; exit 1; }
  exec sudo -E bash "$0" "$@"
fi
clone=$(cd "${1:-$(dirname "$0")/..}" && pwd)
work=${2:-$(mktemp -d /tmp/quathinge-fresh.XXXXXX)}
mkdir -p "$work"
work=$(cd "$work" && pwd)
root=$work/root
start=$(date +%s)
step() { echo; echo "=== ci-fresh-debian: $* ($(date -u +%T), +$(( $(date +%s) - start )) s)"; }
fail() { echo "ci-fresh-debian: FAILED: $*" >&2; exit 1; }

# The commands: README.md's first code block, comments and blank lines dropped.
after=("${@:3}")
mapfile -t commands < <(awk '/^```/ { if (inside) exit; inside = 1; next } inside' "$clone/README.md" |
                          sed -e 's/[[:space:]]*#.*$//' -e '/^[[:space:]]*$/d')
[ ${#commands[@]} -gt 0 ] || fail "no commands in README.md's first code block"
printf 'README commands:\n'; printf '  %s\n' "${commands[@]}"

# The Debian mirror of this machine's apt sources (one-line .list or deb822 .sources), and its security archive.
source_uris() {
  grep -hsE '^[[:space:]]*URIs:' /etc/apt/sources.list.d/*.sources | sed 's/^[[:space:]]*URIs://' | tr ' ' '\n'
  grep -hsE '^[[:space:]]*deb[[:space:]]' /etc/apt/sources.list /etc/apt/sources.list.d/*.list |
    awk '{ for (i = 2; i <= NF; i++) if ($i ~ /^[a-z+]+:\/\//) { print $i; break } }'
}
mirror=$(source_uris | grep -E '/debian/?$' | head -n1 || true)
security=$(source_uris | grep -E '/debian-security/?$' | head -n1 || true)
[ -n "$mirror" ] || fail "no Debian mirror (…/debian) in /etc/apt/sources.list*"
echo "mirror: $mirror; security: ${security:-none}"

mounted=()
cleanup() {
  local status=$? pid i
  # Processes still inside the root (started by the commands above: none should be) would hold the mounts.
  for pid in $(ls /proc | grep -E '^[0-9]+$'); do
    if [ "$(readlink "/proc/$pid/root" 2>/dev/null)" = "$root" ]; then kill -9 "$pid" 2>/dev/null || true; fi
  done
  for (( i = ${#mounted[@]} - 1; i >= 0; i-- )); do
    umount "${mounted[i]}" 2>/dev/null || umount -l "${mounted[i]}" || echo "ci-fresh-debian: could not unmount ${mounted[i]}" >&2
  done
  if [ "${QUATHINGE_FRESH_KEEP:-0}" != 1 ] && ! grep -q " $root/" /proc/mounts; then rm -rf "$root"; fi
  echo "ci-fresh-debian: $( [ $status -eq 0 ] && echo passed || echo "failed ($status)") in $(( $(date +%s) - start )) s"
}
trap cleanup EXIT
mount_in() {  # mount arguments..., target (inside the root)
  local target=${*: -1}
  mkdir -p "$target"
  mount "$@"
  mounted+=("$target")
}

step "debootstrap --variant=minbase bookworm"
command -v debootstrap >/dev/null ||
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq -o DPkg::Lock::Timeout=600 --no-install-recommends debootstrap >/dev/null
debootstrap --variant=minbase bookworm "$root" "$mirror" >"$work/debootstrap.log" 2>&1 ||
  { tail -n 30 "$work/debootstrap.log"; fail "debootstrap"; }
# As a fresh installation has them: the release, its updates and its security archive.
{
  echo "deb $mirror bookworm main"
  echo "deb $mirror bookworm-updates main"
  if [ -n "$security" ]; then echo "deb $security bookworm-security main"; fi
} >"$root/etc/apt/sources.list"
cp /etc/resolv.conf "$root/etc/resolv.conf"
# No service starts inside a chroot.
printf '#!/bin/sh\nexit 101\n' >"$root/usr/sbin/policy-rc.d"
chmod +x "$root/usr/sbin/policy-rc.d"
echo "root: $(du -sh "$root" | cut -f1); packages: $(chroot "$root" dpkg-query -W | wc -l)"

step "the clone of $(git -C "$clone" log -1 --format='%h %s' | cut -c1-70)"
git clone -q --no-checkout "$clone" "$root/root/QuatHinge"
git -C "$root/root/QuatHinge" checkout -q "$(git -C "$clone" rev-parse HEAD)"

mount_in -t proc proc "$root/proc"
mount_in -t sysfs sysfs "$root/sys"
mount_in --bind /dev "$root/dev"
mount_in --bind /dev/pts "$root/dev/pts"
mount_in -t tmpfs tmpfs "$root/dev/shm"

# One command inside the root, in the clone, with a clean environment; timed, and fatal when it fails.
in_root() {
  local command=$1 t0
  t0=$(date +%s)
  chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM=dumb \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    /bin/bash -c "cd /root/QuatHinge && $command" || fail "'$command' in the fresh root"
  echo "ci-fresh-debian: '$command' passed in $(( $(date +%s) - t0 )) s"
}
for command in "${commands[@]}"; do
  step "in the fresh root: $command"
  in_root "$command"
done
step "all README commands passed in a fresh Debian 12 root"
for command in ${after[@]+"${after[@]}"}; do
  step "in the fresh root, after README's commands: $command"
  in_root "$command"
done
