#!/usr/bin/env bash
# The Python client package (client/python) installed with pip and run against the real
# inbetween-server. A virtual environment in $WORK over Debian's python3-grpcio /
# python3-protobuf / python3-setuptools / python3-wheel (--system-site-packages: no package index
# is needed), `pip install --no-index --no-build-isolation` of a copy of the source (pip builds a
# local directory in place and would leave build/ and *.egg-info in the tree; the copy keeps
# proto/ two levels above client/python, where the package's build step finds it), then, with the
# venv's python and no PYTHONPATH: the package's unittest suite (it starts its own servers on
# 127.0.0.1:0; test_art.py and test_streams.py need none), and the package's frame art
# (inbetween/art.py) against the CLI's own SVG frames of two layered drawings
# (client/python/tests/art_parity.py, as client/web/e2e/art_parity.mjs checks the page's): two
# keys (eyes morph, a nose cross-fades, dashes differ), then three keys with Catmull-Rom timing.
# Debian packages: python3-venv, python3-pip-whl, python3-setuptools, python3-setuptools-whl,
# python3-wheel, python3-grpcio, python3-protobuf, protobuf-compiler, protobuf-compiler-grpc.
source "$(dirname "$0")/lib/common.sh"
PY=/usr/bin/python3
"$PY" -c "import grpc, google.protobuf, setuptools, wheel, ensurepip" ||
  { echo "needs python3-grpcio python3-protobuf python3-setuptools python3-wheel python3-venv"; exit 1; }
mkdir -p "$WORK/src/client"
cp -r "$INBETWEEN_SRC/client/python" "$WORK/src/client/python"
cp -r "$INBETWEEN_SRC/proto" "$WORK/src/proto"
rm -rf "$WORK/src/client/python/inbetween/v1" "$WORK/src/client/python/build"
"$PY" -m venv --system-site-packages "$WORK/venv"
VPY="$WORK/venv/bin/python"
PIP_DISABLE_PIP_VERSION_CHECK=1 "$VPY" -m pip install --no-index --no-build-isolation -q \
  "$WORK/src/client/python"
# The installed package, not a source tree: imported from the venv, with its generated stubs.
cd "$WORK"
"$VPY" - <<'PYEOF'
import inbetween, inbetween.v1.inbetween_pb2_grpc, os, sys
assert inbetween.__file__.startswith(sys.prefix), inbetween.__file__
assert os.path.isfile(os.path.join(os.path.dirname(inbetween.__file__), "py.typed"))
print("installed", inbetween.__version__, "at", os.path.dirname(inbetween.__file__))
PYEOF
PYTHONDONTWRITEBYTECODE=1 INBETWEEN_SERVER_BIN="$SERVER_BIN" timeout 780 \
  "$VPY" -m unittest discover -s "$WORK/src/client/python/tests" -v
FACES="$INBETWEEN_SRC/client/web/e2e/data"
"$CLI_BIN" animate "$FACES/face_1.svg" "$FACES/face_2.svg" --frames 7 --method linear \
  --format svg,json --out "$WORK/art_parity_2" -q >/dev/null
"$CLI_BIN" animate "$FACES/face_1.svg" "$FACES/face_2.svg" "$FACES/face_1.svg" --frames 9 \
  --method linear --timing catmull-rom --format svg,json --out "$WORK/art_parity_3" -q >/dev/null
for dir in "$WORK/art_parity_2" "$WORK/art_parity_3"; do
  PYTHONDONTWRITEBYTECODE=1 timeout 120 "$VPY" "$WORK/src/client/python/tests/art_parity.py" "$dir"
done
echo "ok"
