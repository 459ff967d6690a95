#!/usr/bin/env bash
# --tls-cert/--tls-key with a self-signed certificate made here by openssl: the CLI connects with
# --tls-ca; a plaintext client and a client that does not trust the CA are refused. Then mTLS
# with --tls-client-ca: the CLI (no client certificate) is refused.
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/square_hexagon"
command -v openssl >/dev/null || { echo "openssl missing (scripts/setup installs it)"; exit 1; }

openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj "/CN=127.0.0.1" \
  -addext "subjectAltName=IP:127.0.0.1,DNS:localhost" \
  -keyout "$WORK/key.pem" -out "$WORK/cert.pem" 2>/dev/null
openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj "/CN=other" \
  -keyout "$WORK/other-key.pem" -out "$WORK/other.pem" 2>/dev/null

start_server --tls-cert "$WORK/cert.pem" --tls-key "$WORK/key.pem"
"$CLI_BIN" animate "$ex/square.svg" "$ex/hexagon.svg" --frames 4 --out "$WORK/out" \
  --server "$SERVER_ADDR" --tls-ca "$WORK/cert.pem" --quiet
python3 "$INBETWEEN_SRC/tests/e2e/lib/check_frames.py" "$WORK/out/frames.json" 4 0,3
set +e
timeout 20 "$CLI_BIN" --server "$SERVER_ADDR" inspect >/dev/null 2>&1
plain=$?
timeout 20 "$CLI_BIN" --server "$SERVER_ADDR" --tls-ca "$WORK/other.pem" inspect >/dev/null 2>&1
untrusted=$?
set -e
[[ $plain -ne 0 ]] || { echo "a plaintext client got through"; exit 1; }
[[ $untrusted -ne 0 ]] || { echo "a client that does not trust the CA got through"; exit 1; }
kill -9 "$SERVER_PID"
# start_server reads the port from server.log: keep the first log out of its way.
mv "$WORK/server.log" "$WORK/server-1.log"

start_server --tls-cert "$WORK/cert.pem" --tls-key "$WORK/key.pem" --tls-client-ca "$WORK/other.pem"
set +e
timeout 20 "$CLI_BIN" --server "$SERVER_ADDR" --tls-ca "$WORK/cert.pem" inspect >/dev/null 2>&1
no_client_cert=$?
set -e
[[ $no_client_cert -ne 0 ]] || { echo "mTLS accepted a client without a certificate"; exit 1; }
echo "ok"
