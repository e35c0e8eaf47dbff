#!/usr/bin/env bash
# Installs every Debian 12 package masa needs to build, test, run and monitor.
# Idempotent: packages already present are left alone; safe to run again.
#   scripts/install_deps.sh [--bench]
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake pkg-config git
  # core libraries
  libeigen3-dev libyaml-cpp-dev libcli11-dev libomp-dev
  # simulation
  # (mujoco's CMake config names the qhull headers, which libmujoco-dev does not pull in)
  libmujoco-dev libqhull-dev libmujoco-samples
  # transport, tools and Java bindings (lcm-spy needs a JDK to build the types jar, and jchart2d)
  # (liblcm-dev needs glib headers but does not pull them in)
  liblcm-dev libglib2.0-dev liblcm-bin liblcm-java default-jdk-headless libjchart2d-java
  # message authentication (HMAC-SHA256 of the run key, from OpenSSL's libcrypto)
  libssl-dev
  # tests and benchmarks (iproute2 and nftables: the multi-host tests over network namespaces)
  libgtest-dev libgmock-dev libbenchmark-dev iproute2 nftables
  # experiment records (record_grid.sh keeps a grid's environments xz-compressed)
  xz-utils
  # actors on other machines (deploy/train.sh --hosts)
  openssh-client
  # clusters: data-parallel learner ranks and actors as one MPI job (mpirun; srun --mpi=pmix),
  # and Slurm with munge for the test that runs that job on a one-host cluster
  openmpi-bin libopenmpi-dev slurm-wlm munge
  # offscreen rendering of rollouts
  libglfw3-dev xvfb xauth ffmpeg libpng-dev
  # the run directory's learning_curve.png
  gnuplot-nox
  # offline datasets exported to HDF5 (and h5py, to check the export as a Python user reads it)
  libhdf5-dev python3-h5py
  # policies exported to ONNX (masa_export): onnx's protobuf classes (libonnx-dev, which does not
  # pull in libprotobuf-dev), and onnx's checker for the test that reads the files as a user would
  libonnx-dev libprotobuf-dev python3-onnx
  # TensorBoard event files, read back in the tests by an independent decoder (Python's protobuf)
  python3-protobuf
  # the Python module (python/, `import masa`): pybind11 and NumPy; PyYAML reads run configs and,
  # in the tests, the symmetry specs apart from masa's own parser
  pybind11-dev python3-dev python3-numpy python3-yaml
)

# --bench: also the packages that only the comparison benchmarks need (never CI, never a training
# run): LibTorch for bench/libtorch/ and OpenBLAS for its tuned set-up. Installing libopenblas0
# makes OpenBLAS the system's libblas.so.3; masa links no BLAS, and bench/run_learner_vs_libtorch.sh
# picks each set-up's BLAS explicitly.
if [ "${1:-}" = --bench ]; then packages=(libtorch-dev libopenblas-dev); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present."
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install_deps: done."
