#!/usr/bin/env bash
# install-deps.sh: install the Debian 12 packages photosplat needs, skipping
# what is already there (checked with pkg-config or the command itself).
# Called by `make test` and `make run`; needs root or sudo only when something
# is missing. With --bench, also what `make bench` needs (gnuplot for the
# photosplat-bench plots, Embree 3 for bench_accel's baseline); with --fuzz, what `make fuzz` needs (clang and
# its libFuzzer runtime).
set -euo pipefail

missing=()
need_cmd() { command -v "$1" >/dev/null 2>&1 || missing+=("$2"); }
need_pc() { pkg-config --exists "$1" 2>/dev/null || missing+=("$2"); }

need_cmd gcc gcc
need_cmd g++ g++
need_cmd make make
need_cmd pkg-config pkg-config
# Without pkg-config every pkg-config check below would fail; that is fine,
# their packages are then simply installed (apt skips what is present).
need_pc libpng libpng-dev
# JPEG textures (MTL map_Kd) through libjpeg-turbo.
need_pc libjpeg libjpeg62-turbo-dev
need_pc tinyobjloader libtinyobjloader-dev
need_pc cmocka libcmocka-dev
# OpenEXR for --hdr FILE.exr (its C API, OpenEXRCore, from 3.1).
need_pc OpenEXR libopenexr-dev
# photosplat-snap draws with OSMesa (libosmesa6-dev brings the GL headers too).
need_pc osmesa libosmesa6-dev
# The window: GLFW and libGL; its tests run it under a virtual X server.
need_pc glfw3 libglfw3-dev
need_pc gl libgl-dev
need_cmd xvfb-run xvfb
need_cmd xauth xauth
# The OBJ models the loader is tested on (tests/cli_models.sh).
[ -d /usr/share/assimp/models/OBJ ] || missing+=(assimp-testmodels)
# photosplat-ref-mpi and its tests: Open MPI (mpicc and ompi-c.pc from the -dev
# package, mpirun from openmpi-bin).
need_pc ompi-c libopenmpi-dev
need_cmd mpirun openmpi-bin
# The sanitizer runtimes come with gcc on Debian but may be trimmed from images.
[ -e "$(gcc -print-file-name=libasan.so 2>/dev/null)" ] && gcc -print-file-name=libasan.so | grep -q / || missing+=(libasan8)
[ -e "$(gcc -print-file-name=libubsan.so 2>/dev/null)" ] && gcc -print-file-name=libubsan.so | grep -q / || missing+=(libubsan1)

case "${1:-}" in
--bench)
    need_cmd gnuplot gnuplot-nox
    # Embree 3: bench_accel's baseline (bench only; Debian's package ships no .pc file).
    [ -e /usr/include/embree3/rtcore.h ] || missing+=(libembree-dev)
    ;;
--fuzz)
    # clang and its libFuzzer runtime (libclang_rt.fuzzer, in libclang-rt-14-dev).
    need_cmd clang clang
    need_cmd clang++ clang
    if command -v clang >/dev/null 2>&1; then
        rt=$(clang -print-file-name=libclang_rt.fuzzer-x86_64.a 2>/dev/null || true)
        [ -n "$rt" ] && [ -e "$rt" ] || missing+=(libclang-rt-14-dev)
    else
        missing+=(libclang-rt-14-dev)
    fi
    ;;
esac

if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
SUDO=()
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
        SUDO=(sudo)
    else
        echo "install-deps: need root or sudo to install: ${missing[*]}" >&2
        exit 2
    fi
fi
export DEBIAN_FRONTEND=noninteractive
# Try without refreshing the lists first (fast when they are current), then refresh.
if ! "${SUDO[@]}" apt-get install -y --no-install-recommends "${missing[@]}" >/dev/null 2>&1; then
    "${SUDO[@]}" apt-get update -qq
    "${SUDO[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
fi
