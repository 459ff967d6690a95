#!/usr/bin/env bash
# docker/ and deploy/k8s/ without a container engine (tests/e2e/podman_test.sh runs the images
# in containers where Podman can; this covers the rest), checked by containers_check.py:
# `kubectl kustomize deploy/k8s` renders and has the server Deployment with gRPC readiness/liveness
# probes and limits, its Services, ConfigMaps, HPA, PDB, Redis and HAProxy (`haproxy -c` on its
# config); compose.yaml has Redis, 3 replicas, nginx, the gateway and the load generator under the
# `load` profile; every runtime package exists in Debian and together they cover what ldd lists
# for inbetween-server and inbetween-loadgen; every Dockerfile stage starts from its BASE_IMAGE
# and the build stage runs exactly scripts/setup and scripts/build; Redis has a password from a
# secret and maxmemory with noeviction (compose and Kubernetes), the servers --tokens and
# --redis-password-file, the Deployment leaves replicas to its HPA, no secret value is committed.
# Then the commands of compose.yaml and of the Kubernetes manifests run for real on loopback:
# Redis as each starts it (the password on stdin, never in argv) with its authenticating health
# check, replicas with their flags on it (calls without a token refused), the proxy image's nginx
# entrypoint in front, the HEALTHCHECK script, inbetween-loadgen (--token-file) through nginx, and
# a full Redis (noeviction) refusing a new session with STORE_FULL while reads answer.
source "$(dirname "$0")/lib/common.sh"
source "$(dirname "$0")/lib/cluster.sh"
for tool in nginx haproxy node apt-cache dpkg ldd redis-server redis-cli; do
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

"$PY" "$INBETWEEN_SRC/tests/e2e/containers_check.py" --src "$INBETWEEN_SRC" --bin "$INBETWEEN_BIN" \
  --work "$WORK" "${k8s[@]}"
