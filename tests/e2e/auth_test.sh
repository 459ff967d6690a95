#!/usr/bin/env bash
# --tokens FILE: calls without a valid bearer token are refused (UNAUTHENTICATED, CLI exit 5 or
# 3), each token sees only its own sessions; /metrics on --metrics-listen counts the RPCs.
source "$(dirname "$0")/lib/common.sh"
ex="$INBETWEEN_SRC/examples/square_hexagon"
printf '# test tokens\nsecret-alice alice\nsecret-bob bob\n' >"$WORK/tokens"

metrics_port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
start_server --tokens "$WORK/tokens" --metrics-listen "127.0.0.1:$metrics_port"

set +e
"$CLI_BIN" --server "$SERVER_ADDR" inspect 2>"$WORK/none.err"
code_none=$?
"$CLI_BIN" --server "$SERVER_ADDR" --token wrong inspect 2>"$WORK/wrong.err"
code_wrong=$?
set -e
[[ $code_none -ne 0 && $code_wrong -ne 0 ]] || { echo "calls without a valid token succeeded"; exit 1; }
grep -qi "bearer token" "$WORK/none.err" || { cat "$WORK/none.err"; exit 1; }
grep -qi "invalid bearer token" "$WORK/wrong.err" || { cat "$WORK/wrong.err"; exit 1; }

"$CLI_BIN" mesh "$ex/square.svg" "$ex/hexagon.svg" --out "$WORK/mesh" --server "$SERVER_ADDR" \
  --token secret-alice --quiet >"$WORK/mesh.out"
id=$(awk '/^session /{print $2}' "$WORK/mesh.out" | head -1)
"$CLI_BIN" --server "$SERVER_ADDR" --token secret-alice inspect "$id" | grep -q "STAGE_MULTIMESH"
"$CLI_BIN" --server "$SERVER_ADDR" --token secret-alice inspect | grep -q "^$id"
# Bob neither sees nor lists Alice's session.
set +e
"$CLI_BIN" --server "$SERVER_ADDR" --token secret-bob inspect "$id" 2>"$WORK/bob.err"
code_bob=$?
set -e
[[ $code_bob -ne 0 ]] && grep -q "not found" "$WORK/bob.err" || { echo "bob saw alice's session"; cat "$WORK/bob.err"; exit 1; }
if "$CLI_BIN" --server "$SERVER_ADDR" --token secret-bob inspect | grep -q "$id"; then
  echo "bob lists alice's session"; exit 1
fi

curl_metrics() { python3 - "$metrics_port" <<'PY'
import sys, urllib.request
print(urllib.request.urlopen(f"http://127.0.0.1:{sys.argv[1]}/metrics", timeout=5).read().decode())
PY
}
curl_metrics >"$WORK/metrics.txt"
grep -q 'inbetween_rpcs_total{code="OK",method="CreateSession"} 1' "$WORK/metrics.txt" || { cat "$WORK/metrics.txt"; exit 1; }
grep -q 'code="UNAUTHENTICATED"' "$WORK/metrics.txt"
grep -q 'inbetween_rpc_duration_seconds_bucket{code="OK",method="BuildMultimesh",le="+Inf"} 1' "$WORK/metrics.txt"
grep -q '^inbetween_active_sessions 1' "$WORK/metrics.txt"
grep -q '^inbetween_heavy_queue_depth 0' "$WORK/metrics.txt"
# One log line per RPC with its request id.
grep -q 'request=[0-9a-f]*-[0-9]* rpc=BuildMultimesh session='"$id"' status=OK' "$WORK/server.log" || { cat "$WORK/server.log"; exit 1; }
echo "ok"
