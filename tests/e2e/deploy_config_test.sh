#!/usr/bin/env bash
# deploy/: the nginx and HAProxy configs are accepted by the real programs (nginx -t with the
# template included in a minimal main config, haproxy -c), and they keep the settings the
# scale-out relies on (session affinity on x-session-id, long stream timeouts, HTTP/2 upstream).
source "$(dirname "$0")/lib/common.sh"
command -v nginx >/dev/null || { echo "nginx is not installed (scripts/setup)"; exit 1; }
command -v haproxy >/dev/null || { echo "haproxy is not installed (scripts/setup)"; exit 1; }
conf="$INBETWEEN_SRC/deploy/nginx/inbetween.conf"
cfg="$INBETWEEN_SRC/deploy/haproxy/inbetween.cfg"

mkdir -p "$WORK/nginx"
cat >"$WORK/nginx/nginx.conf" <<CONF
worker_processes 1; pid $WORK/nginx/nginx.pid; error_log $WORK/nginx/error.log;
events { worker_connections 64; }
http { access_log off; include $conf; }
CONF
nginx -t -p "$WORK/nginx" -c "$WORK/nginx/nginx.conf"
for want in 'hash $http_x_session_id consistent;' 'grpc_pass grpc://' 'grpc_read_timeout 3600s;' \
            'grpc_send_timeout 3600s;' 'max_fails=' 'grpc_next_upstream error timeout' ' http2;'; do
  grep -qF "$want" "$conf" || { echo "nginx config lacks: $want"; exit 1; }
done

haproxy -c -f "$cfg"
for want in 'balance hdr(x-session-id)' 'hash-type consistent' 'proto h2' 'timeout server 1h'; do
  grep -qF "$want" "$cfg" || { echo "haproxy config lacks: $want"; exit 1; }
done
echo "ok"
