#!/usr/bin/env bash
# Views per second of open3d_gs.distributed on one GPU of the device machine
# (docs/distributed.md "Throughput"): 24-view jobs of playbot_125k at 800x800 rendered
# (i) by one process's batched path (render_batch) and (ii) by the Dask path with one worker.
#
# The device's python3 (3.12 in /opt/torch/.venv, with numpy, no network) cannot load the
# module built here for Debian's 3.11, so cpp/pybind is compiled there, against that python3,
# and linked with the libraries built here. Three steps:
#
#   here:   bash scripts/device/distributed-throughput.sh prepare
#           Builds the libraries (build/, scripts/build.sh), fetches .gl/ and copies the
#           module's shared libraries into .devlibs/ (scripts/device/prepare.sh), and fills
#           .pymod/ (git-ignored): our static libraries and Debian's libimgui.a, the link
#           order and compile flags of cpp/pybind, the Eigen and fmt headers, Debian's
#           pybind11 headers (a fallback only), and Debian's pure-Python dask, distributed,
#           tornado, partd, locket, zict and tblib (the device has their other dependencies).
#   device: a run with carry [.gl, .devlibs, .pymod, shared/data/playbot/playbot_125k.ply,
#           shared/data/playbot/cameras.json] and the command
#           bash scripts/device/distributed-throughput.sh run OUT_DIR [benchmark args]
#           unpacks the loaders, builds the module into /tmp/o3d-device/python, checks it
#           renders, and runs benchmarks/python/distributed_views_per_second.py; all of it
#           is logged in OUT_DIR (log.txt, gpu.txt).
#   here, to test the device's steps against another interpreter (Debian's 3.11, lavapipe):
#           PYTHON=/usr/bin/python3 bash scripts/device/distributed-throughput.sh build DIR
#           PYTHON=/usr/bin/python3 SIZE=64 JOBS=2 JOBS_PNG=1 \
#             bash scripts/device/distributed-throughput.sh measure OUT_DIR
#           (measure is run without unpacking the loaders; shared/ must hold the scene files)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
pymod=.pymod
python=${PYTHON:-python3}

prepare() {
  local build=${BUILD_DIR:-$root/build}
  BUILD_DIR=$build BUILD_TARGETS=open3d_gs_core bash scripts/build.sh
  local module
  module=$(ls "$build"/python/open3d_gs/_core*.so)
  mkdir -p .gl .devlibs  # existing folders: git check-ignore in prepare.sh sees .gitignore's rules
  bash scripts/device/prepare.sh "$module"
  rm -rf "$pymod"  # git-ignored (.gitignore)
  mkdir -p "$pymod/lib"
  # The module's link line, from ninja: objects dropped, our archives and static third-party
  # libraries copied into .pymod/lib, shared ones named by SONAME (they are in .devlibs).
  # (ninja's whole output first: grep -m1 in a pipe would end ninja early, a SIGPIPE that
  # pipefail turns into a failure now and then.)
  local commands link
  commands=$(cd "$build" && ninja -t commands open3d_gs_core)
  link=$(grep -m1 -- "-o python/open3d_gs/_core" <<<"$commands")
  link=${link#: && }  # ": && compiler ... && strip ... && copy ..."
  : >"$pymod/link.txt"
  local word soname
  for word in ${link%% && *}; do
    case "$word" in
      *.a)
        cp -n "$build/$word" "$pymod/lib/" 2>/dev/null || cp -n "$word" "$pymod/lib/"
        echo "static $(basename "$word")" >>"$pymod/link.txt" ;;
      /*.so | /*.so.*)
        soname=$(objdump -p "$word" | awk '$1 == "SONAME" {print $2}')
        echo "shared ${soname:-$(basename "$word")}" >>"$pymod/link.txt" ;;
    esac
  done
  # Compile flags of cpp/pybind's first source: defines, language, optimisation, the
  # floating-point contract. Not -Werror (another compiler may warn) nor -flto (GCC there).
  # xargs undoes ninja's shell quoting (-DOPEN3D_GS_VERSION=\"0.1.0\" becomes one word).
  local compile
  compile=$(grep -m1 -- "-c $root/cpp/pybind/" <<<"$commands")
  xargs -n1 printf '%s\n' <<<"$compile" | while read -r word; do
    case "$word" in
      -D*_EXPORTS) ;;
      -D* | -std=* | -O? | -ffp-contract=* | -fvisibility=*) printf '%s\n' "$word" ;;
    esac
  done >"$pymod/flags.txt"
  # Third-party headers the bindings include (ninja's dependency records), beyond the C and
  # C++ libraries, Python and pybind11: Eigen and fmt.
  local o
  for o in "$build"/cpp/pybind/CMakeFiles/open3d_gs_core.dir/*.o; do
    (cd "$build" && ninja -t deps "${o#"$build"/}")
  done | sed -n 's|^ *\(/usr/include/[^/]*\)/.*|\1|p' | sort -u |
    grep -vE '/(c\+\+|x86_64-linux-gnu|python3[.0-9]*|pybind11|linux|asm|asm-generic|sys|bits)$' >"$pymod/include-dirs.txt"
  local dirs=()
  mapfile -t dirs < <(sed 's|/usr/include/||' "$pymod/include-dirs.txt")
  tar -C /usr/include -czf "$pymod/include.tar.gz" "${dirs[@]}"
  tar -C /usr/include -czf "$pymod/pybind11-debian.tar.gz" pybind11
  # Debian's dask and distributed are pure Python (tornado's one extension is abi3).
  local dist=/usr/lib/python3/dist-packages packages=(dask distributed tornado partd locket zict tblib) p
  for p in "${packages[@]}"; do packages+=("$(cd "$dist" && echo "$p"-*.egg-info)"); done
  # zict's heapdict, a module of one file, and sortedcontainers: the device image lacked
  # heapdict (ModuleNotFoundError from zict on the first run there).
  packages+=(heapdict.py HeapDict-1.0.1.egg-info sortedcontainers sortedcontainers-2.4.0.egg-info)
  tar -C "$dist" --exclude=tests --exclude=__pycache__ -czf "$pymod/pydeps.tar.gz" "${packages[@]}"
  echo "prepare: .pymod holds $(du -sh "$pymod" | cut -f1); carry .gl .devlibs .pymod and the scene files:"
  echo "  [\".gl\", \".devlibs\", \".pymod\", \"shared/data/playbot/playbot_125k.ply\", \"shared/data/playbot/cameras.json\"]"
}

# Compiles cpp/pybind against $python and links it into DIR/python/open3d_gs with the
# package's Python files. Changes nothing outside DIR.
build() {
  local dir=${1:?usage: build DIR}
  local pkg="$dir/python/open3d_gs" obj="$dir/obj" inc="$dir/include"
  mkdir -p "$pkg" "$obj" "$inc"
  tar -C "$inc" -xzf "$pymod/include.tar.gz"
  # pybind11 from the interpreter's own package (the device's image has one); Debian's 2.10
  # headers only where numpy is older than 2: pybind11 before 2.12 reads NumPy 2's dtype
  # records wrongly.
  local includes
  if includes=$("$python" -m pybind11 --includes 2>/dev/null); then
    echo "build: pybind11 $("$python" -c 'import pybind11; print(pybind11.__version__)') of $python"
  else
    local numpy_major
    numpy_major=$("$python" -c 'import numpy; print(numpy.__version__.split(".")[0])')
    if [ "$numpy_major" -ge 2 ]; then
      echo "build: error: $python has no pybind11 package and numpy $numpy_major; Debian's pybind11 2.10 headers do not support NumPy 2" >&2
      return 1
    fi
    tar -C "$inc" -xzf "$pymod/pybind11-debian.tar.gz"
    includes="-isystem $inc $("$python" -c 'import sysconfig; print("-isystem", sysconfig.get_paths()["include"])')"
    echo "build: Debian's pybind11 headers from .pymod (python3 -m pybind11 failed)"
  fi
  local cxx=${CXX:-c++} flags=() suffix
  mapfile -t flags <"$pymod/flags.txt"
  suffix=$("$python" -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')
  echo "build: compiling cpp/pybind with $($cxx --version | head -1) for $("$python" --version)"
  local common=("${flags[@]}" -fPIC -I"$root/cpp" -I"$root/shaders" -isystem "$inc" -isystem "$inc/eigen3")
  # shellcheck disable=SC2206  # the includes are words, as pybind11 prints them
  common+=($includes)
  (cd cpp/pybind && ls -- *.cpp) | sed 's/\.cpp$//' |
    xargs -P "${BUILD_JOBS:-$(nproc)}" -I{} "$cxx" "${common[@]}" -c "$root/cpp/pybind/{}.cpp" -o "$obj/{}.o"
  local libs=() kind name
  while read -r kind name; do
    if [ "$kind" = static ]; then libs+=("$root/$pymod/lib/$name"); else libs+=("-l:$name"); fi
  done <"$pymod/link.txt"
  "$cxx" -shared -o "$pkg/_core$suffix" "$obj"/*.o "${libs[@]}" -L"$root/.devlibs" \
    -Wl,-rpath-link,"$root/.devlibs" -L/usr/lib/x86_64-linux-gnu
  cp -r python/open3d_gs/. "$pkg/"  # the Python files, stubs and py.typed
  echo "build: $pkg/_core$suffix"
}

# The carried libraries the device lacks (by SONAME), for LD_LIBRARY_PATH: where it has its
# own (libstdc++, zlib, X11, ...) that one is used, so python3's other modules keep theirs.
runtime_libs() {
  local dir=${1:?}
  mkdir -p "$dir"
  local f system
  system=$(ldconfig -p | awk '{print $1}')
  for f in "$root"/.devlibs/*; do
    grep -qxF "$(basename "$f")" <<<"$system" || ln -sf "$f" "$dir/"
  done
}

# Builds the module, checks it, and measures; the loaders must be in place (on the device,
# run() unpacks them first; here they are Debian's). SIZE, VIEWS, JOBS, JOBS_PNG set the
# work (default 800, 24, 40, 8); extra arguments go to the benchmark.
measure() {
  local out=${1:?usage: measure OUT_DIR [benchmark args]}
  shift
  mkdir -p "$out"
  "$python" --version
  "$python" -c 'import numpy; print("numpy", numpy.__version__)'
  local work=${WORK_DIR:-/tmp/o3d-device}
  rm -rf "$work"
  build "$work"
  mkdir -p "$work/pydeps"
  tar -C "$work/pydeps" -xzf "$pymod/pydeps.tar.gz"
  runtime_libs "$work/lib"
  export LD_LIBRARY_PATH="$work/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  export PYTHONPATH="$work/python:$work/pydeps${PYTHONPATH:+:$PYTHONPATH}"
  export PYTHONUNBUFFERED=1
  # Dask 2022.12's GPU monitor calls .decode() on what the device's newer pynvml returns as
  # str, and the scheduler fails to start; the benchmark does not need the monitor.
  export DASK_DISTRIBUTED__DIAGNOSTICS__NVML=False
  local carried=("$work"/lib/*)
  [ -e "${carried[0]}" ] || carried=(none)
  echo "measure: carried libraries in use (this machine lacks them): ${carried[*]##*/}"
  "$python" -c 'import dask, distributed; print("dask", dask.__version__, "from", dask.__file__, "distributed", distributed.__version__)'
  # The module renders with Vulkan: one view against the CPU reference.
  "$python" - <<'PY'
import numpy as np
import open3d_gs as o3d
scene = o3d.t.io.read_point_cloud("shared/data/playbot/playbot_125k.ply")
view = o3d.camera.read_cameras_json("shared/data/playbot/cameras.json")[0].camera
images = {}
for backend in ("vulkan", "cpu"):
    r = o3d.visualization.rendering.OffscreenRenderer(64, 64, backend)
    r.scene.add_geometry("scene", scene)
    r.setup_camera(view, rescale=True)
    images[backend] = r.render_to_image()
print("check: vulkan against cpu at 64x64, largest difference", float(np.abs(images["vulkan"] - images["cpu"]).max()))
PY
  local size=${SIZE:-800} bench=(benchmarks/python/distributed_views_per_second.py
    shared/data/playbot/playbot_125k.ply shared/data/playbot/cameras.json)
  local common=(--size "$size" "$size" --views "${VIEWS:-24}" --workers 1)
  # Render only (the batch arrays stay where they were rendered), a job per batch and a third
  # of a job per batch; then with the PNGs written, fewer jobs (zlib on the CPU is slow).
  "$python" "${bench[@]}" "${common[@]}" --jobs "${JOBS:-40}" --batch 24 "$@" | tee "$out/render-only-batch24.txt"
  "$python" "${bench[@]}" "${common[@]}" --jobs "${JOBS:-40}" --batch 8 "$@" | tee "$out/render-only-batch8.txt"
  "$python" "${bench[@]}" "${common[@]}" --jobs "${JOBS_PNG:-8}" --batch 8 --formats png "$@" | tee "$out/png-batch8.txt"
}

# On the device machine: the loaders into /, the NVIDIA driver, then measure.
run() {
  local out=${1:?usage: run OUT_DIR [benchmark args]}
  if ! command -v nvidia-smi >/dev/null 2>&1; then
    echo "run: no nvidia-smi: run unpacks .gl into /, meant for the device machine (here: measure)" >&2
    return 1
  fi
  mkdir -p "$out"
  exec > >(tee "$out/log.txt") 2>&1
  local f
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
  export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
  nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv | tee "$out/gpu.txt" || true
  measure "$@"
}

case "${1:-}" in
  prepare) prepare ;;
  build) shift; build "$@" ;;
  measure) shift; measure "$@" ;;
  run) shift; run "$@" ;;
  *)
    sed -n '2,27p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
    exit 2 ;;
esac
