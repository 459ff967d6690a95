#!/usr/bin/env bash
# The images of docker/Dockerfile and the services of docker/compose.yaml in real containers,
# with Podman (scripts/containers): the server, proxy and redis images assembled from this build's
# binaries (no compile inside a container) on a local Debian 12 base (debootstrap, created once
# and cached), then Redis, three replicas and nginx started as compose describes them, on the
# host network, loopback only. Through nginx the CLI streams a long animation; after its first
# frame the replica container serving it gets SIGKILL: the CLI resumes on another replica and
# its frames.json is identical to an uninterrupted run, and every session still answers (also
# after the container is started again). The stack runs with compose's secrets (made by `up` in
# the test's directory): Redis refuses clients without the password and has maxmemory with
# noeviction, neither the password nor the token is in any process's command line, calls without
# the token are refused, and compose's load generator (its token from the secret file) runs a
# short load through nginx. Skips (exit 77) where Podman cannot run: not root, no podman or runc,
# no base image and no way to make one.
source "$(dirname "$0")/lib/common.sh"
PY=/usr/bin/python3
t0=$SECONDS
skip() { echo "SKIP: $*"; exit 77; }
[[ $EUID -eq 0 ]] || skip "needs root (rootful podman; debootstrap makes the base image)"
command -v podman >/dev/null || skip "podman is not installed (scripts/setup --test installs it)"
command -v runc >/dev/null || skip "runc is not installed (scripts/setup --test installs it)"
"$PY" -c 'import yaml' 2>/dev/null || skip "python3-yaml is not installed (scripts/setup --test)"
containers() { "$PY" "$INBETWEEN_SRC/scripts/containers" "$@"; }

# Podman's overlay driver bind-mounts its storage onto itself and leaves the mount behind; where
# no container can run (a chroot), that mount would outlive the test and pin the root it is in.
release_storage() {
  local graph
  # (podman info itself fails where podman cannot run: then its default root)
  graph=$(containers podman info --format '{{.Store.GraphRoot}}' 2>/dev/null || true)
  graph=${graph:-/var/lib/containers/storage}
  if mountpoint -q "$graph/overlay"; then umount "$graph/overlay" || true; fi
}
if ! containers base >"$WORK/base.log" 2>&1; then
  cat "$WORK/base.log"
  release_storage
  skip "no local base image and none could be made (debootstrap and Debian's mirror needed)"
fi
if ! containers podman run --rm --network host localhost/debian:bookworm-local true \
    >"$WORK/probe.log" 2>&1; then
  cat "$WORK/probe.log"
  release_storage
  skip "podman cannot run a container here"
fi

project="ibsmoke-$$"
state="$WORK/stack.json"
trap 'containers down --project "$project" --volumes >/dev/null 2>&1 || true; cleanup' EXIT

t=$SECONDS
containers prebuilt --bin "$INBETWEEN_BIN" --tag smoke --log "$WORK/build.log"
echo "images in $((SECONDS - t)) s"
t=$SECONDS
# The gateway is left out: its image needs the npm registry (tests/e2e/web_test.sh covers it).
# The secrets (Redis' password, the bearer tokens) are made in the test's directory, not in
# docker/secrets/.
containers up --project "$project" --tag smoke --free-ports --without gateway --state "$state" \
  --secrets-dir "$WORK/secrets"
echo "stack up (redis, 3 replicas healthy, nginx) in $((SECONDS - t)) s"
port() { "$PY" -c 'import json,sys; print(json.load(open(sys.argv[1]))["ports"][sys.argv[2]][sys.argv[3]])' "$state" "$1" "$2"; }
NGINX_ADDR="127.0.0.1:$(port nginx grpc)"
declare -A REPLICA_OF
for n in 1 2 3; do REPLICA_OF["127.0.0.1:$(port "replica$n" grpc)"]="replica$n"; done
TOKEN=$(awk '!/^#/ && NF { print $1; exit }' "$WORK/secrets/tokens")
[[ -n "$TOKEN" ]] || { echo "up made no token in $WORK/secrets/tokens"; exit 1; }

# Redis in its container: no answer without the password; maxmemory with noeviction (the
# password is read inside the container, so it is in no command line here either).
REDIS_PORT=$(port redis redis)
redis_auth() {
  containers podman exec "$project-redis" sh -c \
    "REDISCLI_AUTH=\"\$(head -n 1 /run/secrets/redis_password)\" redis-cli -p $REDIS_PORT $*"
}
out=$(containers podman exec "$project-redis" redis-cli -p "$REDIS_PORT" ping 2>&1 || true)
[[ "$out" == NOAUTH* ]] || { echo "redis answered PING without a password: $out"; exit 1; }
[[ "$(redis_auth config get maxmemory-policy | tail -1)" == noeviction &&
   "$(redis_auth config get maxmemory | tail -1)" =~ ^[1-9][0-9]*$ ]] ||
  { redis_auth config get 'maxmemory*'; echo "redis has no maxmemory with noeviction"; exit 1; }
# No process on this machine (the containers' included) has a secret in its command line.
"$PY" - "$WORK/secrets/redis_password" "$WORK/secrets/tokens" <<'PYCHECK' || exit 1
import os, sys
password = open(sys.argv[1]).readline().rstrip("\r\n")
token = next(l.split()[0] for l in open(sys.argv[2]) if l.split() and not l.startswith("#"))
for pid in filter(str.isdigit, os.listdir("/proc")):
    try:
        argv = open(f"/proc/{pid}/cmdline", "rb").read()
    except OSError:
        continue
    for name, value in (("the Redis password", password), ("the token", token)):
        if value.encode() in argv:
            sys.exit(f"{name} is in the command line of pid {pid}: {argv[:80]!r}")
PYCHECK
# Tokens are on: through nginx, a call without one is refused.
out=$("$CLI_BIN" --server "$NGINX_ADDR" inspect 00000000 2>&1 || true)
grep -qE "UNAUTHENTICATED|missing bearer token" <<<"$out" ||
  { echo "a call without a token: $out"; exit 1; }
echo "secrets: redis needs its password (maxmemory, noeviction), no secret in any argv," \
     "tokens required"

cli() { "$CLI_BIN" --server "$NGINX_ADDR" --token "$TOKEN" "$@"; }
session_of() { grep -oE '^session [0-9a-f]+' "$1" | awk '{print $2}'; }
inspect() { containers podman inspect --format "$2" "$project-$1"; }
# nginx's access log, read as a file (`podman logs` takes too long between the pause and the kill).
NGINX_LOG=$(inspect nginx '{{.HostConfig.LogConfig.Path}}')
nginx_log() { cat "$NGINX_LOG"; }

# The long stream of tests/e2e/scale_test.sh: more frames than the buffers between a replica and
# a paused CLI hold, so the replica still has frames to send when it is killed.
WALK=("$INBETWEEN_SRC"/examples/walk/0[1-8]_*.svg)
FRAMES=6000
LONG=(animate "${WALK[@]}" --frames "$FRAMES" --format json)
t=$SECONDS
cli -q "${LONG[@]}" --out "$WORK/reference" >"$WORK/reference.out"
SESSIONS=("$(session_of "$WORK/reference.out")")
echo "reference run through nginx in $((SECONDS - t)) s"

# chaos A: the stream paused after its first frame, the replica container that built its
# session (nginx's log: upstream of the last BuildMultimesh) killed, the CLI resumed; 2 when the
# stream ran on another replica than the one that built it (nothing interrupted: again). The
# kill is SIGKILL to the container's first process from here, as `podman kill` sends it, but
# within milliseconds: a replica makes the 6000 frames in about a second, and they would all be
# in the loopback buffers before a slower kill.
chaos() {
  local out="$WORK/chaos-$1" err="$WORK/chaos-$1.err" pid line sid up victim resume n
  declare -A pids
  for n in 1 2 3; do pids[replica$n]=$(inspect "replica$n" '{{.State.Pid}}'); done
  cli "${LONG[@]}" --out "$out" >"$out.txt" 2>"$err" &
  pid=$!
  wait_first_frame "$pid" "$err" || { cat "$err"; echo "no frame arrived"; return 1; }
  kill -STOP "$pid"
  line=$(nginx_log | grep '/inbetween.v1.Inbetween/BuildMultimesh ' | tail -1)
  sid=$(grep -oE 'session=[0-9a-f]+' <<<"$line" | cut -d= -f2)
  # "upstream=A, B 0.123": the last upstream nginx tried is the one that answered.
  up=$(sed -E 's/.* upstream=(.*) [0-9.]+$/\1/' <<<"$line" | awk -F', ' '{print $NF}')
  victim=${REPLICA_OF[$up]:-}
  [[ -n "$victim" ]] || { echo "no replica for nginx upstream '$up': $line"; return 1; }
  kill -9 "${pids[$victim]}"
  echo "session $sid streams from $victim ($up): SIGKILL its container"
  containers podman wait "$project-$victim" >/dev/null
  kill -CONT "$pid"
  wait "$pid" || { cat "$err"; echo "the CLI failed after the kill"; return 1; }
  containers start --state "$state" "$victim"
  [[ "$(session_of "$out.txt")" == "$sid" ]] || { echo "the CLI ran another session"; return 1; }
  SESSIONS+=("$sid")
  cmp "$WORK/reference/frames.json" "$out/frames.json" ||
    { echo "frames differ from the uninterrupted run"; return 1; }
  resume=$(grep -oE 'retry: Inbetween attempt 1 failed .*resuming at frame [0-9]+' "$err" |
           grep -oE '[0-9]+$' | head -1 || true)
  if [[ -z "$resume" ]]; then
    if nginx_log | grep "/inbetween.v1.Inbetween/Inbetween .*session=$sid " | grep -vq "upstream=$up"; then
      echo "the stream ran on another replica than $victim; again"
      return 2
    fi
    cat "$err"; echo "no mid-stream resume reported"; return 1
  fi
  [[ "$resume" -gt 0 && "$resume" -lt "$FRAMES" ]] || { echo "resumed at frame $resume"; return 1; }
  echo "resumed at frame $resume on another replica; $FRAMES frames identical"
}
t=$SECONDS
rc=0
for a in 1 2 3; do
  rc=0
  chaos "$a" || rc=$?
  [[ $rc -eq 2 ]] || break
done
[[ $rc -eq 0 ]] || { echo "the replica kill mid-stream failed"; exit 1; }
echo "kill mid-stream and restart in $((SECONDS - t)) s"

# Nothing lost: every session answers through nginx.
for sid in "${SESSIONS[@]}"; do
  [[ -n "$sid" ]] || { echo "a run printed no session id"; exit 1; }
  cli inspect "$sid" >"$WORK/inspect.out" 2>&1 || { cat "$WORK/inspect.out"; echo "session $sid lost"; exit 1; }
  grep -q "$sid" "$WORK/inspect.out" || { cat "$WORK/inspect.out"; echo "inspect $sid: no id"; exit 1; }
done

# compose's load generator in its container (profile `load`), its token from the mounted secret
# file: a short load through nginx, no call refused for want of a token.
t=$SECONDS
containers load --state "$state" --json "$WORK/load.json" -- --studios 2 --seconds 5 \
  --max-requests 40 >"$WORK/load.log" 2>&1 || { cat "$WORK/load.log"; echo "loadgen failed"; exit 1; }
"$PY" - "$WORK/load.json" <<'PYCHECK' || { cat "$WORK/load.log"; exit 1; }
import json, sys
report = json.load(open(sys.argv[1]))
errors = report.get("errors_by_code", {})
if report.get("requests", 0) < 1 or "UNAUTHENTICATED" in errors or report.get("lost_sessions"):
    sys.exit(f"the load through nginx: {json.dumps(report)[:600]}")
print(f"load: {report['requests']} requests with the secret's token, errors {errors}")
PYCHECK
echo "load in $((SECONDS - t)) s"
echo "ok: ${#SESSIONS[@]} sessions, 1 replica container killed mid-stream, 0 lost, frames identical;" \
     "$((SECONDS - t0)) s"
