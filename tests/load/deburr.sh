#!/usr/bin/env bash
# Load figure: typical deburr requests over loopback with wrk (Debian package `wrk`).
# Starts the release binary on a temporary database, registers tool 7, then runs
# wrk with 64 connections on 2 threads. Usage: tests/load/deburr.sh [seconds] [distinct]
# Without `distinct` every request is the same (answered from the answer cache after the first);
# with it, every request has its own cut amount and is solved (tests/load/deburr-distinct.lua).
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds="${1:-15}"
script=tests/load/deburr.lua
if [ "${2:-}" = distinct ]; then script=tests/load/deburr-distinct.lua; fi
cargo build --release -p kerf-server --quiet
workdir="$(mktemp -d)"
trap 'kill "$server" 2>/dev/null || true; rm -rf "$workdir"' EXIT
./target/release/kerf --database "$workdir/kerf.db" --bind 127.0.0.1:18181 > "$workdir/kerf.log" 2>&1 &
server=$!
for _ in $(seq 50); do curl -sf http://127.0.0.1:18181/healthz >/dev/null && break; sleep 0.1; done
curl -sf -X PUT http://127.0.0.1:18181/api/v1/tools/7 -H 'content-type: application/json' \
     -d '{"kind": "ball", "radius": 3}' >/dev/null
RUST_LOG=warn wrk -t2 -c64 -d"${seconds}s" --latency -s "$script" http://127.0.0.1:18181/api/v1/deburr
