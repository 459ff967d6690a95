#!/usr/bin/env bash
# docker/ and deploy/k8s/ without a container engine (tests/e2e/podman_test.sh runs the images
# in containers where Podman can; this covers the rest), checked by containers_check.py:
# `kubectl kustomize deploy/k8s` renders and has the server Deployment with gRPC readiness/liveness
# probes and limits, its Services, ConfigMaps, HPA, PDB, Redis and HAProxy (`haproxy -c` on its
# config); compose.yaml has Redis, 3 replicas, nginx, the gateway and the load generator under the
# `load` profile; every runtime package exists in Debian and together they cover what ldd lists
# for inbetween-server and inbetween-loadgen; every Dockerfile stage starts from its BASE_IMAGE
# and the build stage runs exactly scripts/setup and scripts/build. Then the commands of
# compose.yaml and of the Deployment run for real on loopback: replicas with their flags on a real
# Redis, the proxy image's nginx entrypoint in front, the HEALTHCHECK script, inbetween-loadgen
# through nginx.
source "$(dirname "$0")/lib/common.sh"
source "$(dirname "$0")/lib/cluster.sh"
for tool in nginx haproxy node apt-cache dpkg ldd; do
  command -v "$tool" >/dev/null || { echo "$tool is not installed (scripts/setup)"; exit 1; }
done
"$PY" -c 'import yaml, grpc' || { echo "python3-yaml and python3-grpcio are needed (scripts/setup)"; exit 1; }

k8s=()
if command -v kubectl >/dev/null; then
  kubectl kustomize "$INBETWEEN_SRC/deploy/k8s" >"$WORK/k8s.yaml"
  k8s=(--k8s "$WORK/k8s.yaml")
else
  echo "SKIP: kubectl not found: deploy/k8s is not rendered or checked (scripts/setup installs" \
       "Debian's kubernetes-client)"
fi

start_redis
"$PY" "$INBETWEEN_SRC/tests/e2e/containers_check.py" --src "$INBETWEEN_SRC" --bin "$INBETWEEN_BIN" \
  --work "$WORK" --redis-port "$REDIS_PORT" "${k8s[@]}"
