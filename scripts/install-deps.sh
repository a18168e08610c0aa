#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Install what is missing (Debian packages only). Root or sudo required.
set -euo pipefail
# protobuf-c-compiler, libprotobuf-c-dev: rcal-rt's EGM messages (firmware_host/egm.proto, issue 49);
# protobuf-compiler, python3-protobuf: the simulated EGM controller of the tests (tests/firmware_host/test_egm_sim.py).
# liblapack-dev, libblas-dev: the reference LAPACK and BLAS archives rcal links by their own place
# (cmake/rcal_lapack.cmake; never the alternatives ATLAS or OpenBLAS switch); gfortran: their run-time.
PKGS=(cmake make gcc pkg-config libserialport-dev liblapacke-dev liblapack-dev libblas-dev gfortran libcmocka-dev
      gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi clang libclang-rt-14-dev
      cppcheck clang-tidy valgrind binutils libgsl-dev
      python3 python3-pytest python3-numpy python3-venv python3-pip python3-setuptools python3-wheel liburdfdom-tools libexpat1-dev chromium fonts-dejavu-core
      groff-base colcon python3-colcon-cmake python3-colcon-ros
      protobuf-c-compiler libprotobuf-c-dev protobuf-compiler python3-protobuf strace)
# groff-base: renders the generated man pages (pkg_man_completion); colcon, python3-colcon-cmake,
# python3-colcon-ros: read package.xml as colcon does (pkg_colcon_package). libexpat1-dev: URDF (rch_urdf*.c)
# and RSI's XML (firmware_host/rt_rsi.c). protobuf-c-compiler, libprotobuf-c-dev: EGM's messages
# (firmware_host/egm.proto); protobuf-compiler, python3-protobuf: the simulated ABB controller (comp_egm_sim).
# strace: a calibration opens each input once (tests/tools/host/fit/calib_read_once.sh, issue 50).
# --list: print the package list (.ci/run installs it with apt-get itself)
if [ "${1:-}" = "--list" ]; then
  echo "${PKGS[@]}"
  exit 0
fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "installing: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
