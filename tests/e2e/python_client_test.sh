#!/usr/bin/env bash
# The Python client (client/python) against the real inbetween-server: stubs generated from the
# proto with protoc + grpc_python_plugin into a temp dir, then the module's unittest suite (it
# starts its own servers on 127.0.0.1:0). Debian's python3-grpcio/python3-protobuf: /usr/bin/python3.
source "$(dirname "$0")/lib/common.sh"
PY=/usr/bin/python3
"$PY" -c "import grpc, google.protobuf" || { echo "python3-grpcio/python3-protobuf missing"; exit 1; }
"$INBETWEEN_SRC/client/python/generate_stubs.sh" "$WORK/stubs"
cd "$INBETWEEN_SRC/client/python"
PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$WORK/stubs:$INBETWEEN_SRC/client/python" \
  INBETWEEN_SERVER_BIN="$SERVER_BIN" timeout 240 "$PY" -m unittest discover -s tests -v
echo "ok"
