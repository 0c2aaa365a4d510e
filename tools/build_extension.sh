#!/usr/bin/env bash
# Builds the Blender extension that carries Lantern's native core:
#   1. the `lantern` wheel (native core + Python package) for this Python and platform, in an
#      incremental CMake tree (build/ext), so that a rebuild after a small change is quick;
#   2. a staged copy of addon/ with the wheel under wheels/ and a manifest that lists it and
#      names the platform it was built for (Blender 4.2+: `wheels = [...]`, `platforms = [...]`);
#   3. dist/lantern-<version>-<platform>.zip, built and validated by Blender's own extension
#      tool (blender_ext.py build, from the bpy in the venv).
# Environment: PYTHON (default .venv/bin/python, else the shared venv), LANTERN_CUDA=OFF|ON|AUTO
# (default OFF: a CPU-only core; ON needs nvcc; the CUDA runtime is linked statically, see
# docs/extension.md), LANTERN_CUDA_ARCHS (default 90; releases: "75;80;86;89;90-real;90-virtual"),
# LANTERN_EXT_BUILD (the build folder; default build/ext, build/ext-cuda with CUDA on),
# LANTERN_EXT_REUSE=1 (package the core tools/setup.sh built in build/py, with that tree's own
# CUDA settings, instead of compiling a second one: the tests use it, so that a clean CI clone
# compiles the core once; the wheel is the same pip wheel of the same sources).
# Prints the path of the zip on its last line.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

py=${PYTHON:-}
if [ -z "$py" ]; then
  for cand in .venv/bin/python /work/main/.venv/bin/python python3.11; do
    if command -v "$cand" >/dev/null 2>&1; then py=$cand; break; fi
  done
fi
[ -n "$py" ] || { echo "build_extension: no Python 3.11 found (set PYTHON)" >&2; exit 1; }
export PATH="$(dirname "$(command -v "$py")"):$PATH"  # the venv's cmake and ninja

version=$("$py" -c "import tomllib; print(tomllib.load(open('addon/blender_manifest.toml','rb'))['version'])")
pyver=$("$py" -c "import tomllib; print(tomllib.load(open('pyproject.toml','rb'))['project']['version'])")
if [ "$version" != "$pyver" ]; then
  echo "build_extension: addon/blender_manifest.toml says $version, pyproject.toml $pyver" >&2
  exit 1
fi

# ---- 1. the wheel ----
cuda=${LANTERN_CUDA:-OFF}
archs=${LANTERN_CUDA_ARCHS:-90}
build=${LANTERN_EXT_BUILD:-build/ext}
[ "$cuda" != "OFF" ] && [ -z "${LANTERN_EXT_BUILD:-}" ] && build=build/ext-cuda
# OpenVDB (Volume objects) is a shared library the extension cannot carry yet: off unless
# LANTERN_EXT_OPENVDB=ON (a machine whose Blender finds libopenvdb; docs/volumes.md)
wheel_args=(-C build-dir="$root/$build/cmake" -C cmake.define.LANTERN_BUILD_TESTS=OFF
            -C cmake.define.LANTERN_CUDA="$cuda" -C cmake.define.CMAKE_CUDA_ARCHITECTURES="$archs"
            -C cmake.define.LANTERN_OPENVDB="${LANTERN_EXT_OPENVDB:-OFF}")
if [ "${LANTERN_EXT_REUSE:-0}" = 1 ]; then
  # setup.sh's tree, configured exactly as it configured it (a define that differed would make
  # CMake rebuild every object, here and again at the next setup.sh)
  cache=build/py/CMakeCache.txt
  [ -f "$cache" ] || { echo "build_extension: LANTERN_EXT_REUSE=1 but no $cache (run tools/setup.sh)" >&2; exit 1; }
  cache_value() { sed -n "s/^$1:[A-Z]*=//p" "$cache" | head -1; }
  cuda="$(cache_value LANTERN_CUDA) (build/py)"
  export CMAKE_ARGS="-DCMAKE_CUDA_ARCHITECTURES=$(cache_value CMAKE_CUDA_ARCHITECTURES) -DLANTERN_CUDA_KEEP_PTX=$(cache_value LANTERN_CUDA_KEEP_PTX)"
  wheel_args=(-C build-dir="$root/build/py")
fi
wheeldir=$build/wheelhouse
rm -rf "$wheeldir"
mkdir -p "$wheeldir"
log=$build/wheel.log
echo "build_extension: building the lantern wheel (CUDA $cuda; log in $log)"
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}
if ! "$py" -m pip wheel . --no-build-isolation --no-deps -w "$wheeldir" "${wheel_args[@]}" \
    >"$log" 2>&1; then
  echo "build_extension: the wheel build failed; the end of $log:" >&2
  tail -40 "$log" >&2
  exit 1
fi
wheel=$(ls "$wheeldir"/lantern-*.whl)
wheel_name=$(basename "$wheel")
# the native core must be inside and must not depend on anything outside libc/libstdc++/libm
# (Embree is loaded at run time when present; CUDA's runtime is static, the driver is loaded
# at run time)
"$py" - "$wheel" <<'EOF'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
cores = [n for n in names if n.startswith("lantern/_core") and n.endswith(".so")]
if len(cores) != 1:
    sys.exit(f"build_extension: the wheel holds {cores or 'no'} native core(s), want one")
if b"libopenvdb.so" in zipfile.ZipFile(sys.argv[1]).read(cores[0]):
    print("build_extension: note: this core links libopenvdb (LANTERN_EXT_OPENVDB=ON or a "
          "reused setup.sh tree): it loads only where libopenvdb and its libraries are "
          "installed", file=sys.stderr)
EOF

# the platform the wheel was built for, in Blender's words (linux_x86_64 -> linux-x64)
tag=${wheel_name%.whl}
tag=${tag##*-}
case "$tag" in
  *linux*x86_64) platform=linux-x64 ;;
  *linux*aarch64) platform=linux-arm64 ;;
  win_amd64) platform=windows-x64 ;;
  win_arm64) platform=windows-arm64 ;;
  macosx*arm64) platform=macos-arm64 ;;
  macosx*x86_64) platform=macos-x64 ;;
  *) echo "build_extension: unknown wheel platform tag '$tag'" >&2; exit 1 ;;
esac

# ---- 2. the staged extension ----
stage=$build/stage/lantern
rm -rf "$build/stage"
mkdir -p "$stage/wheels"
git ls-files -co --exclude-standard -- addon | while read -r f; do
  [ -f "$f" ] || continue
  mkdir -p "$stage/$(dirname "${f#addon/}")"
  cp "$f" "$stage/${f#addon/}"
done
cp "$wheel" "$stage/wheels/"
"$py" - "$stage/blender_manifest.toml" "$wheel_name" "$platform" <<'EOF'
import sys
path, wheel, platform = sys.argv[1:]
text = open(path).read()
if "\nwheels" in text or "\nplatforms" in text or "\nblender_version_max" in text:
    sys.exit("build_extension: addon/blender_manifest.toml already names wheels, platforms or "
             "blender_version_max; the build adds them")
# the Blender versions whose Python loads the wheel: 4.2 to 5.0 run Python 3.11, 5.1 runs 3.13
python_tag = wheel.split("-")[2]
version_max = {"cp311": "5.1.0"}.get(python_tag)
if python_tag not in ("cp311", "cp313"):
    sys.exit(f"build_extension: no Blender release runs Python {python_tag}")
extra = f'blender_version_max = "{version_max}"\n' if version_max else ""
if python_tag == "cp313":
    text = text.replace('blender_version_min = "4.2.0"', 'blender_version_min = "5.1.0"')
# top-level keys must come before the first [table]
head, sep, tail = text.partition("\n[")
head = head.rstrip("\n") + (f'\n\n# added by tools/build_extension.sh\n{extra}'
                            f'platforms = ["{platform}"]\nwheels = ["./wheels/{wheel}"]\n')
open(path, "w").write(head + (sep + tail if sep else "\n"))
EOF

# ---- 3. the zip, through Blender's extension tool (it validates the manifest and wheels) ----
ext_tool=$("$py" - <<'EOF'
import importlib.util, os
spec = importlib.util.find_spec("bpy")
base = os.path.dirname(spec.origin)
for dirpath, _, files in os.walk(base):
    if "blender_ext.py" in files and dirpath.endswith(os.path.join("bl_pkg", "cli")):
        print(os.path.join(dirpath, "blender_ext.py"))
        break
EOF
)
[ -n "$ext_tool" ] || { echo "build_extension: Blender's blender_ext.py not found (bpy)" >&2; exit 1; }
mkdir -p dist
out="dist/lantern-$version-$platform.zip"
rm -f "$out"
"$py" "$ext_tool" build --source-dir "$stage" --output-filepath "$out" >"$build/zip.log" 2>&1 || {
  cat "$build/zip.log" >&2; exit 1; }
"$py" "$ext_tool" validate "$out" >>"$build/zip.log" 2>&1 || { cat "$build/zip.log" >&2; exit 1; }
echo "build_extension: $wheel_name ($platform) in"
echo "$root/$out"
