#!/usr/bin/env bash
# The Debian packages (cmake/InbetweenPackaging.cmake, docs/install.md) on a fresh Debian 12:
# cpack builds `inbetween` and `inbetween-server` from this build; their fields and files are
# checked; both are installed with `apt-get install ./PKG.deb` into a clean debootstrap minbase
# root, so their Depends (from dpkg-shlibdeps) are fetched from Debian's mirror; there the
# installed `inbetween animate` runs on examples/square_hexagon, embedded and against the
# installed `inbetween-server`.
#
# Opt-in (INBETWEEN_DEB_TEST=1, e.g. `INBETWEEN_DEB_TEST=1 ctest -L deb`): it needs root, a cached
# root tarball and the mirror, and a minute or two, so the default run reports it skipped (exit 77,
# SKIP_RETURN_CODE in tests/e2e/CMakeLists.txt). Skipped too when INBETWEEN_SKIP_DEB_TEST is set.
# The root: INBETWEEN_DEBIAN_ROOT_TAR, default ~/.cache/inbetween-fresh/bookworm-newcomer.tar, a
# tar of a `debootstrap --variant=minbase bookworm` root with ca-certificates and the host's
# apt configuration; the host's resolver and extra CA certificates are copied in at each run.
skip() { echo "SKIP: $*"; exit 77; }
[[ -z "${INBETWEEN_SKIP_DEB_TEST:-}" ]] || skip "INBETWEEN_SKIP_DEB_TEST is set"
[[ "${INBETWEEN_DEB_TEST:-}" == 1 ]] ||
  skip "the .deb test is opt-in (root, network to Debian's mirror, 1-2 minutes):" \
       "INBETWEEN_DEB_TEST=1 ctest -L deb"
[[ $(id -u) -eq 0 ]] || skip "needs root (chroot, mount)"
for tool in cpack dpkg-deb dpkg-shlibdeps fakeroot chroot mount; do
  command -v "$tool" >/dev/null || skip "$tool is not installed (dpkg-dev, fakeroot)"
done
root_tar=${INBETWEEN_DEBIAN_ROOT_TAR:-${XDG_CACHE_HOME:-$HOME/.cache}/inbetween-fresh/bookworm-newcomer.tar}
[[ -f "$root_tar" ]] ||
  skip "no Debian 12 root at $root_tar (INBETWEEN_DEBIAN_ROOT_TAR): make one with" \
       "debootstrap --variant=minbase --include=ca-certificates bookworm DIR MIRROR; tar -C DIR -cf TAR ."

source "$(dirname "$0")/lib/common.sh"
ROOT=$(mktemp -d)
SERVER_IN_ROOT=""
deb_cleanup() {
  [[ -n "$SERVER_IN_ROOT" ]] && kill -9 "$SERVER_IN_ROOT" 2>/dev/null
  umount "$ROOT/proc" 2>/dev/null
  mountpoint -q "$ROOT/proc" || rm -rf --one-file-system "$ROOT"
}
trap 'deb_cleanup; cleanup' EXIT

# ---- the packages ----
(cd "$WORK" && cpack --config "$INBETWEEN_BIN/CPackConfig.cmake" -B "$WORK/packages") >"$WORK/cpack.log" 2>&1 ||
  { cat "$WORK/cpack.log"; echo "cpack failed"; exit 1; }
cli_deb=$(ls "$WORK"/packages/inbetween_*.deb)
server_deb=$(ls "$WORK"/packages/inbetween-server_*.deb)
version=$(sed -nE 's/^project\(inbetween VERSION ([0-9.]+).*/\1/p' "$INBETWEEN_SRC/CMakeLists.txt")
for deb in "$cli_deb" "$server_deb"; do
  dpkg-deb -f "$deb" Package Version Maintainer Depends Description | sed 's/^/  /'
  [[ $(dpkg-deb -f "$deb" Version) == "$version-1" ]] || { echo "$deb: version is not $version-1"; exit 1; }
  dpkg-deb -f "$deb" Depends | grep -q 'libgrpc++' || { echo "$deb: Depends lacks gRPC"; exit 1; }
done
files() { dpkg-deb -c "$1" | awk '$1 !~ /^d/ {print $6}' | sort | tr '\n' ' '; }
[[ $(files "$cli_deb") == "./usr/bin/inbetween " ]] ||
  { dpkg-deb -c "$cli_deb"; echo "inbetween.deb should hold /usr/bin/inbetween alone"; exit 1; }
[[ $(files "$server_deb") == "./usr/bin/inbetween-loadgen ./usr/bin/inbetween-server " ]] ||
  { dpkg-deb -c "$server_deb"; echo "inbetween-server.deb should hold the server and loadgen"; exit 1; }

# ---- a fresh Debian 12: the cached root, the host's resolver and CA trust, /proc ----
tar -C "$ROOT" -xf "$root_tar"
cp /etc/resolv.conf "$ROOT/etc/" 2>/dev/null || true
if ls /usr/local/share/ca-certificates/*.crt >/dev/null 2>&1; then
  mkdir -p "$ROOT/usr/local/share/ca-certificates"
  cp /usr/local/share/ca-certificates/*.crt "$ROOT/usr/local/share/ca-certificates/"
  chroot "$ROOT" update-ca-certificates >/dev/null 2>&1 || true
fi
mount -t proc proc "$ROOT/proc"
mkdir -p "$ROOT/tmp/debs" "$ROOT/tmp/example"
cp "$cli_deb" "$server_deb" "$ROOT/tmp/debs/"
cp "$INBETWEEN_SRC"/examples/square_hexagon/*.svg "$ROOT/tmp/example/"
# A clean environment inside: nothing of the host's (or ctest's) PATH or library paths.
root_env=(/usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root DEBIAN_FRONTEND=noninteractive)
in_root() { chroot "$ROOT" "${root_env[@]}" "$@"; }

in_root bash -c 'apt-get update -qq && apt-get install -y -qq /tmp/debs/*.deb' >"$WORK/apt.log" 2>&1 ||
  { tail -30 "$WORK/apt.log"; echo "apt-get install of the packages failed"; exit 1; }
missing=$(in_root ldd /usr/bin/inbetween /usr/bin/inbetween-server /usr/bin/inbetween-loadgen | grep 'not found' || true)
[[ -z "$missing" ]] || { echo "$missing"; echo "Depends miss a shared library"; exit 1; }
in_root dpkg -s libopenblas0-pthread >/dev/null || { echo "Recommends libopenblas0-pthread not installed"; exit 1; }

in_root inbetween animate /tmp/example/square.svg /tmp/example/hexagon.svg --frames 12 \
  --out /tmp/embedded --quiet >/dev/null
python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$ROOT/tmp/embedded/frames.json" 12 0,11

# chroot and env exec the server: $! is its pid.
chroot "$ROOT" "${root_env[@]}" inbetween-server --listen 127.0.0.1:0 >"$WORK/server.log" 2>&1 &
SERVER_IN_ROOT=$!
disown "$SERVER_IN_ROOT"  # killed by deb_cleanup, without bash's job report
addr=""
for _ in $(seq 1 200); do
  addr=$(grep -oE 'inbetween-server listening on 127\.0\.0\.1:[0-9]+' "$WORK/server.log" | head -1 |
         awk '{print $4}' || true)
  [[ -n "$addr" ]] && break
  kill -0 "$SERVER_IN_ROOT" 2>/dev/null || { cat "$WORK/server.log"; echo "installed server died"; exit 1; }
  sleep 0.05
done
[[ -n "$addr" ]] || { cat "$WORK/server.log"; echo "installed server did not report its port"; exit 1; }
in_root inbetween animate /tmp/example/square.svg /tmp/example/hexagon.svg --frames 12 \
  --out /tmp/remote --quiet --server "$addr" >/dev/null
python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$ROOT/tmp/remote/frames.json" 12 0,11
echo "ok"
