# Sourced by the scripts that drive the job server (scripts/pipeline.sh, bench/compare-integrators.sh).
#   start_rcfd_server BIN DATA_DIR LOG_DIR
# starts BIN/rcfd-server on a free loopback port with its SQLite and artifacts in DATA_DIR, waits until
# it listens (or prints its log and exits if it dies first), stops it when the calling script exits,
# and exports RCFD_SERVER and RCFD_TOKEN for the rcfd client. The server takes RCFD_TOKEN when it is
# set, else it keeps (or creates) one in DATA_DIR.
start_rcfd_server() {
  local bin=$1 data=$2 logs=$3
  mkdir -p "$data" "$logs"
  "$bin/rcfd-server" --data-dir "$data" --listen 127.0.0.1:0 --workers 1 >"$logs/server.out" 2>"$logs/server.log" &
  rcfd_server_pid=$!
  trap 'kill "$rcfd_server_pid" 2>/dev/null || true; wait "$rcfd_server_pid" 2>/dev/null || true' EXIT
  for _ in $(seq 1 200); do
    grep -q '^listening on ' "$logs/server.out" 2>/dev/null && break
    kill -0 "$rcfd_server_pid" 2>/dev/null || { cat "$logs/server.log" >&2; exit 1; }
    sleep 0.05
  done
  RCFD_SERVER=$(sed -n 's/^listening on //p' "$logs/server.out" | head -n1)
  [ -n "$RCFD_SERVER" ] || { echo "rcfd-server did not start listening; log: $logs/server.log" >&2; exit 1; }
  RCFD_TOKEN=${RCFD_TOKEN:-$(cat "$data/token")}
  export RCFD_SERVER RCFD_TOKEN
}
