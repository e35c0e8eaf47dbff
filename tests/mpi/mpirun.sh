#!/usr/bin/env bash
# mpirun as the MPI tests use it on any machine: as root where CI runs as root (Open MPI refuses it
# unless told), more ranks than cores (a 2-core CI machine runs 4 processes), no core binding (it
# would pin oversubscribed ranks onto one core), and no network interfaces but loopback searched.
#   tests/mpi/mpirun.sh -np 2 PROGRAM [ARGS] [: -np 2 PROGRAM2 ...]
set -euo pipefail
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
exec mpirun --oversubscribe --bind-to none --mca btl self,vader,tcp --mca btl_tcp_if_include lo \
  --mca oob_tcp_if_include lo "$@"
