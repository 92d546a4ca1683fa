#!/bin/sh
# DXF import benchmark (docs/spec/dxf.md): kerf's reader on a 100 000-entity drawing
# (solver/benches/dxf.rs, criterion's thrpt in entities/s), then ezdxf reading the same file
# (tests/load/dxf_ezdxf.py), in one run. Needs ezdxf (pip install ezdxf==1.4.5; the venv
# ~/.cache/kerf-venv has it after `pip install -r tests/requirements.txt`).
set -eu
cd "$(dirname "$0")/../.."
python="${PYTHON:-$HOME/.cache/kerf-venv/bin/python}"
cargo bench -p kerf-solver --bench dxf -- --warm-up-time 1 --measurement-time 10 2>&1 | tee /tmp/kerf-dxf-bench.txt
file=$(sed -n 's/^the drawing: //p' /tmp/kerf-dxf-bench.txt)
"$python" tests/load/dxf_ezdxf.py "$file" 3
