# A one-host Slurm cluster for the tests (sourced): munge and slurmctld + slurmd on this machine
# with a generated slurm.conf in a scratch folder. Needs root and Debian's slurm-wlm and munge
# (scripts/install_deps.sh). local_slurm_start prints "SKIP: why" and returns 1 where one of them is
# missing, so that a test can skip with the reason; where all are present a cluster that does not
# come up is a failure: it prints "FAIL: why" and returns 2.
#   local_slurm_start DIR [CPUS]   (exports SLURM_CONF; the daemons stop with local_slurm_stop)
# CPUS (default: this machine's) is what the node declares: a job as a user types it for a bigger
# machine (sbatch --ntasks 16) runs here too, its tasks sharing the cores.

local_slurm_start() {
  slurm_dir=$1
  [ "$(id -u)" -eq 0 ] || { echo "SKIP: a local Slurm cluster needs root (slurmd runs jobs as their users)"; return 1; }
  local bin
  for bin in slurmctld slurmd munged mungekey srun sbatch scancel squeue; do
    command -v "$bin" > /dev/null || [ -x "/usr/sbin/$bin" ] ||
      { echo "SKIP: $bin is missing (scripts/install_deps.sh installs slurm-wlm and munge)"; return 1; }
  done
  mkdir -p "$slurm_dir"/{state,spool,log}
  # munge: one key, its directories owned by munge, the daemon as munge (reused when running).
  if ! munge -n 2> /dev/null | unmunge > /dev/null 2>&1; then
    mkdir -p /etc/munge /run/munge /var/log/munge /var/lib/munge
    [ -s /etc/munge/munge.key ] || mungekey --create --keyfile=/etc/munge/munge.key > /dev/null 2>&1 ||
      { echo "FAIL: mungekey could not make /etc/munge/munge.key"; return 2; }
    chown -R munge:munge /etc/munge /run/munge /var/log/munge /var/lib/munge
    chmod 0400 /etc/munge/munge.key
    runuser -u munge -- /usr/sbin/munged > /dev/null 2>&1 || true
    sleep 0.5
    munge -n 2> /dev/null | unmunge > /dev/null 2>&1 || { echo "FAIL: munged does not answer"; return 2; }
  fi
  local host cpus mem
  host=$(hostname -s)
  cpus=${2:-$(nproc)}
  mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 8 / 10 ))
  # Ports of their own, so that a cluster of an earlier run or another test does not answer.
  # proctrack/pgid: with proctrack/linuxproc, scancel ended the step while two actors of the job
  # lived on (measured); real clusters use proctrack/cgroup, which a container cannot set up.
  local port=$(( 16800 + RANDOM % 400 * 2 ))
  cat > "$slurm_dir/slurm.conf" << CONF
ClusterName=masatest
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/pgid
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
StateSaveLocation=$slurm_dir/state
SlurmdSpoolDir=$slurm_dir/spool
SlurmctldPidFile=$slurm_dir/slurmctld.pid
SlurmdPidFile=$slurm_dir/slurmd.pid
SlurmctldLogFile=$slurm_dir/log/slurmctld.log
SlurmdLogFile=$slurm_dir/log/slurmd.log
KillWait=5
# The node's CPUs as declared here, not as counted (CPUS may exceed this machine's).
SlurmdParameters=config_overrides
InactiveLimit=0
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=masa Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:8
CONF
  export SLURM_CONF="$slurm_dir/slurm.conf"
  /usr/sbin/slurmctld -f "$SLURM_CONF" -i || { echo "FAIL: slurmctld did not start (see $slurm_dir/log)"; return 2; }
  /usr/sbin/slurmd -f "$SLURM_CONF" || { echo "FAIL: slurmd did not start (see $slurm_dir/log)"; local_slurm_stop; return 2; }
  local _
  for _ in $(seq 1 100); do
    sinfo -h -o %T 2> /dev/null | grep -qE '^idle' && return 0
    sleep 0.2
  done
  echo "FAIL: the local Slurm node did not come up (see $slurm_dir/log)"
  tail -n 20 "$slurm_dir"/log/*.log 2> /dev/null || true
  local_slurm_stop
  return 2
}

local_slurm_stop() {
  local f
  for f in "$slurm_dir/slurmd.pid" "$slurm_dir/slurmctld.pid"; do
    [ -f "$f" ] && kill "$(cat "$f")" 2> /dev/null || true
  done
  sleep 0.5
}
