#!/usr/bin/env bash
# Generates the Python protobuf + gRPC stubs of proto/inbetween/v1/inbetween.proto into OUT_DIR
# (as OUT_DIR/inbetween/v1/inbetween_pb2{,_grpc}.py). The stubs are build/test artefacts, never
# committed. Needs Debian's protobuf-compiler and protobuf-compiler-grpc (grpc_python_plugin).
# Usage: client/python/generate_stubs.sh OUT_DIR
set -euo pipefail
out="${1:?usage: generate_stubs.sh OUT_DIR}"
here="$(cd "$(dirname "$0")" && pwd)"
proto_root="$here/../../proto"
plugin="${GRPC_PYTHON_PLUGIN:-/usr/bin/grpc_python_plugin}"
[[ -x "$plugin" ]] || { echo "generate_stubs: $plugin not found (apt-get install protobuf-compiler-grpc)" >&2; exit 1; }
mkdir -p "$out"
protoc -I "$proto_root" --python_out="$out" --grpc_python_out="$out" \
  --plugin=protoc-gen-grpc_python="$plugin" "$proto_root/inbetween/v1/inbetween.proto"
