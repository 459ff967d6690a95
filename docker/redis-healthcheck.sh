#!/bin/sh
# The redis image's health check (docker/Dockerfile HEALTHCHECK, compose's healthcheck): PING,
# authenticated with the password of REDIS_PASSWORD_FILE (default /run/secrets/redis_password,
# first line), which redis-cli takes from REDISCLI_AUTH rather than from its argv. Healthy only
# on PONG: redis-cli exits 0 after an error reply such as NOAUTH. Arguments: more redis-cli
# options before PING (scripts/containers adds -p PORT on the host network).
set -eu
file=${REDIS_PASSWORD_FILE:-/run/secrets/redis_password}
REDISCLI_AUTH=$(sed -n -e '1{s/\r$//;p;q}' "$file")
export REDISCLI_AUTH
[ "$(redis-cli "$@" ping)" = PONG ]
