#!/usr/bin/env bash
# The Python client (client/python) against the real inbetween-server: stubs generated from the
# proto with protoc + grpc_python_plugin into a temp dir, then the module's unittest suite (it
# starts its own servers on 127.0.0.1:0; tests/test_art.py needs none). Then the module's frame
# art (inbetween/art.py) against the CLI's own SVG frames of two layered drawings
# (client/python/tests/art_parity.py, as client/web/e2e/art_parity.mjs checks the page's): two
# keys (eyes morph, a nose cross-fades, dashes differ), then three keys with Catmull-Rom timing.
# Debian's python3-grpcio/python3-protobuf: /usr/bin/python3.
source "$(dirname "$0")/lib/common.sh"
PY=/usr/bin/python3
"$PY" -c "import grpc, google.protobuf" || { echo "python3-grpcio/python3-protobuf missing"; exit 1; }
"$INBETWEEN_SRC/client/python/generate_stubs.sh" "$WORK/stubs"
cd "$INBETWEEN_SRC/client/python"
PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$WORK/stubs:$INBETWEEN_SRC/client/python" \
  INBETWEEN_SERVER_BIN="$SERVER_BIN" timeout 240 "$PY" -m unittest discover -s tests -v
FACES="$INBETWEEN_SRC/client/web/e2e/data"
"$CLI_BIN" animate "$FACES/face_1.svg" "$FACES/face_2.svg" --frames 7 --method linear \
  --format svg,json --out "$WORK/art_parity_2" -q >/dev/null
"$CLI_BIN" animate "$FACES/face_1.svg" "$FACES/face_2.svg" "$FACES/face_1.svg" --frames 9 \
  --method linear --timing catmull-rom --format svg,json --out "$WORK/art_parity_3" -q >/dev/null
for dir in "$WORK/art_parity_2" "$WORK/art_parity_3"; do
  PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$WORK/stubs:$INBETWEEN_SRC/client/python" \
    timeout 120 "$PY" tests/art_parity.py "$dir"
done
echo "ok"
