#!/usr/bin/env bash
# The proxy image's nginx (docker/Dockerfile, stage `proxy`; docker/compose.yaml): renders
# deploy/nginx/inbetween.conf with its upstream `server` lines replaced by $INBETWEEN_REPLICAS
# (each keeps the template's options) and its listener by $INBETWEEN_PROXY_LISTEN, then runs
# nginx in the foreground as the current user (non-root in the image). Outside a container it
# runs the same way: tests/e2e/containers_test.sh starts it on loopback in front of real servers.
#   INBETWEEN_REPLICAS      "HOST:PORT HOST:PORT ..." (required)
#   INBETWEEN_PROXY_LISTEN  nginx `listen` address, PORT or HOST:PORT (default 8080)
#   INBETWEEN_NGINX_TEMPLATE  default /etc/inbetween/nginx/inbetween.conf
#   INBETWEEN_NGINX_DIR       nginx prefix for its config, pid and temp files (default /tmp/nginx)
# nginx resolves the replicas' names once, at start: a replica that comes back on another
# address is reached again after nginx restarts (meanwhile its sessions go to the others).
set -euo pipefail
template=${INBETWEEN_NGINX_TEMPLATE:-/etc/inbetween/nginx/inbetween.conf}
dir=${INBETWEEN_NGINX_DIR:-/tmp/nginx}
listen=${INBETWEEN_PROXY_LISTEN:-8080}
replicas=${INBETWEEN_REPLICAS:?set INBETWEEN_REPLICAS to the replicas, "HOST:PORT HOST:PORT ..."}
mkdir -p "$dir/tmp"

awk -v listen="$listen" -v replicas="$replicas" '
  BEGIN { n = split(replicas, r, /[ \t]+/) }
  /^[ \t]*listen 127\.0\.0\.1:[0-9]+ http2;/ { sub(/127\.0\.0\.1:[0-9]+/, listen); listens++ }
  /^[ \t]*server 127\.0\.0\.1:[0-9]+[ ;]/ {
    if (!servers++) {
      indent = $0; sub(/server.*/, "", indent)
      options = $0; sub(/^[ \t]*server [^ ;]+/, "", options)
      for (i = 1; i <= n; i++) if (r[i] != "") print indent "server " r[i] options
    }
    next
  }
  { print }
  END {
    if (listens != 1 || servers == 0) {
      print "nginx-entrypoint: the template has no `listen 127.0.0.1:PORT http2;` or no " \
            "`server 127.0.0.1:PORT` line" > "/dev/stderr"
      exit 1
    }
  }' "$template" >"$dir/inbetween.conf"

# As root, nginx would run its workers as nobody, who cannot write $dir; keep the current user.
user=""
[[ $(id -u) -eq 0 ]] && user="user root root;"
cat >"$dir/nginx.conf" <<CONF
$user
worker_processes ${INBETWEEN_NGINX_WORKERS:-auto};
pid $dir/nginx.pid;
error_log stderr ${INBETWEEN_NGINX_LOG_LEVEL:-warn};
events { worker_connections 1024; }
http {
  log_format inbetween '\$remote_addr "\$request" \$status session=\$http_x_session_id '
                       'upstream=\$upstream_addr \$request_time';
  access_log /dev/stdout inbetween;
  client_body_temp_path $dir/tmp/body;
  proxy_temp_path $dir/tmp/proxy;
  fastcgi_temp_path $dir/tmp/fastcgi;
  uwsgi_temp_path $dir/tmp/uwsgi;
  scgi_temp_path $dir/tmp/scgi;
  include $dir/inbetween.conf;
}
CONF
exec nginx -e stderr -p "$dir" -c "$dir/nginx.conf" -g 'daemon off;'
