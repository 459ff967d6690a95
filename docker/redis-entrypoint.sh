#!/bin/sh
# The redis image's entrypoint (docker/Dockerfile, stage `redis`; docker/compose.yaml): runs
# redis-server with `requirepass` read from a secret file and fed to it on stdin
# (`redis-server -` reads configuration from stdin before the command line's options), so the
# password is in no process's argv or environment and in no file but the secret itself.
#   REDIS_PASSWORD_FILE  default /run/secrets/redis_password (compose's secret `redis_password`);
#                        its first line is the password, as inbetween-server
#                        --redis-password-file reads it.
# Arguments: redis-server options (the image's CMD, compose's `command:`). Without a readable,
# non-empty password file Redis does not start: the session store is never exposed without a
# password by accident. tests/e2e/containers_check.py runs this script on loopback.
set -eu
file=${REDIS_PASSWORD_FILE:-/run/secrets/redis_password}
if [ ! -r "$file" ]; then
  echo "inbetween-redis: cannot read the password file $file (mount the secret redis_password" \
       "or set REDIS_PASSWORD_FILE)" >&2
  exit 1
fi
# The first line without a trailing CR, with " and \ escaped for Redis' double-quoted strings.
password=$(sed -n -e '1{s/\r$//;s/[\\"]/\\&/g;p;q}' "$file")
if [ -z "$password" ]; then
  echo "inbetween-redis: the password file $file has an empty first line" >&2
  exit 1
fi
# A here-document: redis-server replaces this shell (it gets the signals as PID 1) and reads the
# line from a pipe.
exec redis-server - "$@" <<CONFIG
requirepass "$password"
CONFIG
