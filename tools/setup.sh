#!/usr/bin/env bash
# Idempotent set-up of a Debian 12 machine for Lantern: Debian packages that are missing, a
# Python 3.11 venv in .venv with the pinned requirements, and an (incremental) build of the
# `lantern` package with its native core. Quiet when there is nothing to do.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

# ---- Debian packages ----
need=()
for pkg in build-essential cmake git zlib1g-dev libembree-dev libgtest-dev; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || need+=("$pkg")
done
# optional: OpenVDB and Boost's headers (OpenVDB's need them) for Volume objects; without them
# the core builds and Volume objects warn "built without OpenVDB"
want_opt=()
for pkg in libopenvdb-dev libboost-dev libboost-iostreams-dev python3-openvdb; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || want_opt+=("$pkg")
done
py=$(command -v python3.11 || true)
if [ -z "$py" ]; then
  need+=(python3.11 python3.11-venv python3.11-dev)
fi
sudo_cmd=""
[ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
if [ ${#need[@]} -gt 0 ] || [ ${#want_opt[@]} -gt 0 ]; then
  $sudo_cmd apt-get update -qq || echo "setup: apt-get update failed"
fi
if [ ${#need[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${need[*]}"
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${need[@]}" >/dev/null
  py=$(command -v python3.11)
fi
if [ ${#want_opt[@]} -gt 0 ]; then
  echo "setup: installing optional Debian packages: ${want_opt[*]}"
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${want_opt[@]}" >/dev/null ||
    echo "setup: could not install ${want_opt[*]}: Lantern builds without OpenVDB (Volume objects warn)"
fi

# ---- Python venv with pinned requirements ----
if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv with $py"
  "$py" -m venv .venv
fi
stamp=.venv/.requirements.sha256
want=$(sha256sum requirements.txt | cut -d' ' -f1)
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing pinned Python packages (bpy is large; first time only)"
  .venv/bin/python -m pip install -q -r requirements.txt
  echo "$want" > "$stamp"
fi

# ---- build and install lantern (incremental: build/py keeps the CMake tree) ----
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}
# CUDA targets: LANTERN_CUDA_ARCHS, else SASS (and PTX) for the compute capability of each GPU
# nvidia-smi lists (an RTX 3080 is 86, an H100 90; sm_90 code does not load on an 8.x card; a
# driver too old to report it: 90), else PTX only as CI builds it (no ptxas: ~30 CPU-minutes of
# SASS nothing here could run, and one configuration for this script, tools/render_default.sh
# and .ci/run, so that switching between them does not rebuild every CUDA object)
archs=${LANTERN_CUDA_ARCHS:-}
if [ -z "$archs" ]; then
  if command -v nvidia-smi >/dev/null 2>&1 && nvidia-smi -L 2>/dev/null | grep -q "^GPU"; then
    archs=$(nvidia-smi --query-gpu=compute_cap --format=csv,noheader 2>/dev/null \
            | tr -d ' .' | grep -E '^[0-9]+$' | sort -u | paste -sd ';')
    [ -n "$archs" ] || archs=90
  else
    archs=90-virtual
  fi
fi
export CMAKE_ARGS="${CMAKE_ARGS:-} -DCMAKE_CUDA_ARCHITECTURES=$archs -DLANTERN_CUDA_KEEP_PTX=$PWD/build/ptx"
log=build/setup-build.log
mkdir -p build
if ! .venv/bin/python -m pip install --no-build-isolation --no-deps . >"$log" 2>&1; then
  echo "setup: building lantern failed; the end of $log:" >&2
  tail -40 "$log" >&2
  exit 1
fi
.venv/bin/python -c "import lantern; assert lantern.native_available(), lantern.native_error()"
