# Helpers for e2e tests of replicas behind a proxy (source after common.sh): a loopback
# redis-server, inbetween-server replicas on Redis that can be killed and restarted on the same
# port, and nginx run as the current user from deploy/nginx/inbetween.conf. Every process goes
# into PIDS, so common.sh's EXIT trap kills it.

PY=/usr/bin/python3

free_port() {
  "$PY" -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}

# start_redis: sets REDIS_PORT and REDIS_PID (no persistence; retries if the port was taken).
start_redis() {
  command -v redis-server >/dev/null || { echo "redis-server is not installed"; return 1; }
  local port
  for _ in 1 2 3 4 5; do
    port=$(free_port)
    redis-server --port "$port" --bind 127.0.0.1 --save '' --appendonly no --loglevel warning \
      >"$WORK/redis.log" 2>&1 &
    REDIS_PID=$!
    PIDS+=("$REDIS_PID")
    for _ in $(seq 1 100); do
      redis-cli -h 127.0.0.1 -p "$port" ping 2>/dev/null | grep -q PONG && break
      kill -0 "$REDIS_PID" 2>/dev/null || break
      sleep 0.05
    done
    # Ours only (another process may have taken the port first; ours then exits).
    if redis-cli -h 127.0.0.1 -p "$port" info server 2>/dev/null | tr -d '\r' |
        grep -qx "process_id:$REDIS_PID"; then
      REDIS_PORT=$port
      return 0
    fi
    kill -9 "$REDIS_PID" 2>/dev/null || true
  done
  cat "$WORK/redis.log"; echo "redis-server did not start" >&2; return 1
}

# start_replica N PORT [flags]: replica N (log $WORK/replica-N.log, appended across restarts) on
# 127.0.0.1:PORT (0 = a free port); sets REPLICA_PID[N] and REPLICA_PORT[N].
declare -A REPLICA_PID REPLICA_PORT
start_replica() {
  local n=$1 port=$2
  shift 2
  local log="$WORK/replica-$n.log" start_line=0 addr=""
  [[ -f "$log" ]] && start_line=$(wc -l <"$log")
  "$SERVER_BIN" --listen "127.0.0.1:$port" "$@" >>"$log" 2>&1 &
  REPLICA_PID[$n]=$!
  PIDS+=("${REPLICA_PID[$n]}")
  for _ in $(seq 1 400); do
    addr=$(tail -n +"$((start_line + 1))" "$log" |
           grep -oE 'inbetween-server listening on 127\.0\.0\.1:[0-9]+' | head -1 | awk '{print $4}' || true)
    if [[ -n "$addr" ]]; then
      REPLICA_PORT[$n]=${addr##*:}
      return 0
    fi
    kill -0 "${REPLICA_PID[$n]}" 2>/dev/null || { cat "$log"; echo "replica $n died" >&2; return 1; }
    sleep 0.05
  done
  cat "$log"; echo "replica $n did not report its port" >&2; return 1
}

# kill_replica N: SIGKILL, and wait until it is gone.
kill_replica() {
  kill -9 "${REPLICA_PID[$1]}" 2>/dev/null || true
  wait "${REPLICA_PID[$1]}" 2>/dev/null || true
}

# start_nginx PORT...: nginx in $WORK/nginx, from deploy/nginx/inbetween.conf with its three
# upstream servers replaced by 127.0.0.1:PORT... and its listener by a free loopback port; sets
# NGINX_ADDR and NGINX_PID. Access log $WORK/nginx/access.log, one line per call:
# "session|upstream, upstream...|uri|status, status..." (several upstreams when nginx retried).
start_nginx() {
  command -v nginx >/dev/null || { echo "nginx is not installed (scripts/setup)"; return 1; }
  local dir="$WORK/nginx" template="$INBETWEEN_SRC/deploy/nginx/inbetween.conf" port user=""
  mkdir -p "$dir/tmp"
  # The template's replicas, one line each; replaced in order by ours.
  [[ $(grep -cE '^\s*server 127\.0\.0\.1:[0-9]+ ' "$template") -eq $# ]] ||
    { echo "expected $# upstream server lines in $template" >&2; return 1; }
  # As root, nginx would run its workers as nobody; keep them the current user.
  [[ $EUID -eq 0 ]] && user="user root root;"
  for _ in 1 2 3 4 5; do
    port=$(free_port)
    "$PY" - "$template" "$dir/inbetween.conf" "$port" "$@" <<'PYEOF'
import re, sys
template, out, listen, ports = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
text = open(template).read()
text, n = re.subn(r"listen 127\.0\.0\.1:\d+ http2;", f"listen 127.0.0.1:{listen} http2;", text)
assert n == 1, "listen line not found in the template"
it = iter(ports)
text = re.sub(r"(^\s*server )127\.0\.0\.1:\d+ ", lambda m: f"{m.group(1)}127.0.0.1:{next(it)} ",
              text, flags=re.M)
open(out, "w").write(text)
PYEOF
    # master_process off: one process, so the EXIT trap's SIGKILL leaves no orphaned worker.
    cat >"$dir/nginx.conf" <<CONF
$user
master_process off;
pid $dir/nginx.pid;
error_log $dir/error.log info;
events { worker_connections 512; }
http {
  log_format inbetween '\$http_x_session_id|\$upstream_addr|\$request_uri|\$upstream_status';
  access_log $dir/access.log inbetween;
  client_body_temp_path $dir/tmp/body;
  proxy_temp_path $dir/tmp/proxy;
  fastcgi_temp_path $dir/tmp/fastcgi;
  uwsgi_temp_path $dir/tmp/uwsgi;
  scgi_temp_path $dir/tmp/scgi;
  include $dir/inbetween.conf;
}
CONF
    nginx -p "$dir" -c "$dir/nginx.conf" -g 'daemon off;' >"$dir/stdout.log" 2>&1 &
    NGINX_PID=$!
    PIDS+=("$NGINX_PID")
    for _ in $(seq 1 200); do
      if ! kill -0 "$NGINX_PID" 2>/dev/null; then break; fi
      if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
        NGINX_ADDR="127.0.0.1:$port"
        return 0
      fi
      sleep 0.05
    done
    kill -9 "$NGINX_PID" 2>/dev/null || true
    cat "$dir/stdout.log" "$dir/error.log" 2>/dev/null || true
  done
  echo "nginx did not start" >&2; return 1
}

# start_haproxy PORT...: HAProxy from deploy/haproxy/inbetween.cfg with its servers replaced by
# 127.0.0.1:PORT... and its frontend by a free loopback port; sets HAPROXY_ADDR, HAPROXY_PID.
start_haproxy() {
  command -v haproxy >/dev/null || { echo "haproxy is not installed (scripts/setup)"; return 1; }
  local template="$INBETWEEN_SRC/deploy/haproxy/inbetween.cfg" port
  [[ $(grep -cE '^\s*server r[0-9]+ 127\.0\.0\.1:[0-9]+' "$template") -eq $# ]] ||
    { echo "expected $# server lines in $template" >&2; return 1; }
  for _ in 1 2 3 4 5; do
    port=$(free_port)
    "$PY" - "$template" "$WORK/haproxy.cfg" "$port" "$@" <<'PYEOF'
import re, sys
template, out, listen, ports = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
text = open(template).read()
text, n = re.subn(r"bind 127\.0\.0\.1:\d+ ", f"bind 127.0.0.1:{listen} ", text)
assert n == 1, "bind line not found in the template"
it = iter(ports)
text = re.sub(r"(^\s*server r\d+ )127\.0\.0\.1:\d+", lambda m: f"{m.group(1)}127.0.0.1:{next(it)}",
              text, flags=re.M)
open(out, "w").write(text)
PYEOF
    haproxy -db -f "$WORK/haproxy.cfg" >"$WORK/haproxy.log" 2>&1 &
    HAPROXY_PID=$!
    PIDS+=("$HAPROXY_PID")
    for _ in $(seq 1 200); do
      if ! kill -0 "$HAPROXY_PID" 2>/dev/null; then break; fi
      if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
        HAPROXY_ADDR="127.0.0.1:$port"
        return 0
      fi
      sleep 0.05
    done
    kill -9 "$HAPROXY_PID" 2>/dev/null || true
    cat "$WORK/haproxy.log" 2>/dev/null || true
  done
  echo "haproxy did not start" >&2; return 1
}
