#!/usr/bin/env bash
# Set up (idempotent), then render Blender's default scene with Lantern to out/default.{exr,png}.
# Flags are passed on: --samples N --percentage P --output PATH_WITHOUT_EXTENSION
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash tools/setup.sh
exec .venv/bin/python tools/render_default.py "$@"
