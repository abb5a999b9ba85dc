#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for trying scripts/slurm_ablate.sh without a
# cluster (scripts/test_slurm.sh, docs/CLUSTER.md). Works as root in a container without
# systemd: the daemons run in their own daemon mode, not as services.
#   bash scripts/slurm_local.sh          start (idempotent: installs, configures and starts
#                                        only what is missing, then waits for the node)
#   bash scripts/slurm_local.sh stop     shut slurmctld, slurmd and munged down
#   bash scripts/slurm_local.sh status   sinfo, or why there is none
# The configuration goes where Debian's Slurm reads it, /etc/slurm/slurm.conf, never into
# the repository. A slurm.conf this script did not write is left alone (it exits instead).
# SLURM_LOCAL_TIMEOUT (seconds, default 90) bounds the wait for the node to come up.
set -euo pipefail

action="${1:-start}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
conf=/etc/slurm/slurm.conf
marker="# Written by saresgs scripts/slurm_local.sh"
host="$(hostname -s)"
timeout="${SLURM_LOCAL_TIMEOUT:-90}"
ctld_pid=/run/slurmctld.pid
slurmd_pid=/run/slurmd.pid
munge_pid=/run/munge/munged.pid
log_dir=/var/log/slurm

# Whether pid $1 is alive and is program $2 (a stale pid file may name a recycled pid: only
# our own daemons are ever signalled). A daemon that exited may linger as a zombie until
# init reaps it: that one is gone.
pid_alive() {
  local pid="$1" name="$2"
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 1
  [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$name" ] || return 1
  [ "$(awk '{print $3}' "/proc/$pid/stat" 2>/dev/null)" != Z ]
}

# The pid in pid file $1 when that process is alive and is program $2.
live_pid() {
  local pid
  pid="$(cat "$1" 2>/dev/null)" || return 1
  pid_alive "$pid" "$2" || return 1
  echo "$pid"
}

# Waits up to $3 seconds for pid $1 (program $2) to exit.
wait_gone() {
  local pid="$1" name="$2" secs="$3" i
  for ((i = 0; i < secs * 2; i++)); do
    pid_alive "$pid" "$name" || return 0
    sleep 0.5
  done
  return 1
}

# TERM to pid $1 (program $2) if it is still there, then KILL if it lingers past 20 s.
stop_pid() {
  local pid="$1" name="$2"
  pid_alive "$pid" "$name" || return 0
  echo "slurm_local: stopping $name (pid $pid)"
  kill -TERM "$pid" 2>/dev/null || true
  if ! wait_gone "$pid" "$name" 20; then
    echo "slurm_local: $name (pid $pid) ignored TERM, killing it" >&2
    kill -KILL "$pid" 2>/dev/null || true
  fi
}

# Stops slurmctld and slurmd. Their pids are taken first: slurmd removes its pid file as
# soon as it starts shutting down but may take a few seconds more (it tries to tell the
# controller that its jobs' epilogs finished). `scontrol shutdown` stops slurmctld and
# asks every slurmd to exit with it; TERM catches a daemon that did not get the message.
stop_slurm() {
  local ctld sd
  ctld="$(live_pid "$ctld_pid" slurmctld)" || ctld=""
  sd="$(live_pid "$slurmd_pid" slurmd)" || sd=""
  [ -n "$ctld$sd" ] || return 0
  echo "slurm_local: shutting Slurm down (slurmctld ${ctld:-not running}, slurmd ${sd:-not running})"
  if [ -n "$ctld" ]; then
    scontrol shutdown >/dev/null 2>&1 || true
    wait_gone "$ctld" slurmctld 20 || true
  fi
  [ -z "$sd" ] || wait_gone "$sd" slurmd 20 || true
  [ -z "$ctld" ] || stop_pid "$ctld" slurmctld
  [ -z "$sd" ] || stop_pid "$sd" slurmd
}

show_logs() {
  local f
  for f in "$log_dir/slurmctld.log" "$log_dir/slurmd.log" /var/log/munge/munged.log; do
    [ -f "$f" ] || continue
    echo "---- last lines of $f" >&2
    tail -n 25 "$f" >&2
  done
}

stop_all() {
  local m
  stop_slurm
  m="$(live_pid "$munge_pid" munged)" && stop_pid "$m" munged
  echo "slurm_local: stopped"
}

case "$action" in
  stop) stop_all; exit 0 ;;
  status) exec sinfo ;;
  start) ;;
  *) echo "usage: $0 [start|stop|status]" >&2; exit 2 ;;
esac

[ "$(id -u)" -eq 0 ] || { echo "slurm_local: run as root (the daemons, their spool and /etc/slurm)" >&2; exit 1; }

# 1. Packages: Debian's slurm-wlm (slurmctld, slurmd, the client commands) and munge,
# Slurm's authentication. Their postinst scripts only enable systemd units, which never run
# here; everything below starts the daemons by hand.
missing=()
for p in slurm-wlm munge; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] || bash "${here}/apt_install.sh" "${missing[@]}"

# 2. Munge: one key shared by every daemon and client of the cluster (here, one host).
# munge's postinst usually makes it; a missing key is created here, readable by munge only.
if [ ! -s /etc/munge/munge.key ]; then
  echo "slurm_local: creating /etc/munge/munge.key"
  install -d -o munge -g munge -m 0700 /etc/munge
  if command -v mungekey >/dev/null; then
    mungekey --create --keyfile=/etc/munge/munge.key --force
  else
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 status=none
  fi
  chown munge:munge /etc/munge/munge.key
  chmod 0400 /etc/munge/munge.key
fi
# systemd would make /run/munge (RuntimeDirectory=munge); without it we do.
install -d -o munge -g munge -m 0755 /run/munge
install -d -o munge -g munge -m 0700 /var/lib/munge /var/log/munge
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  m="$(live_pid "$munge_pid" munged)" && stop_pid "$m" munged  # alive but not answering
  echo "slurm_local: starting munged"
  # As the munge user, as the packaged unit does; root would need --force.
  runuser -u munge -- /usr/sbin/munged
  for ((i = 0; i < 20; i++)); do
    munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break
    sleep 0.5
  done
  munge -n | unmunge >/dev/null || { echo "slurm_local: munged does not answer" >&2; show_logs; exit 1; }
fi

# 3. slurm.conf for this host. The node is declared with what nproc and free say (memory a
# bit below the total: a node that claims more than slurmd finds is drained), and
# config_overrides keeps a small mismatch from draining it anyway. No cgroups (a container
# may not let us have them): linuxproc tracks a job's processes through /proc, task/none
# binds nothing, and there is no accounting. cons_tres with CR_Core hands out single cores,
# so an array of one-core shards runs nproc tasks at a time. PropagatePrioProcess=1: a job
# runs at the nice value sbatch was started with (`nice -n 5 sbatch ...`).
cpus="$(nproc)"
mem_total="$(free -m | awk '/^Mem:/ {print $2}')"
real_mem=$((mem_total * 95 / 100))
new_conf="$(mktemp)"
trap 'rm -f "$new_conf"' EXIT
cat >"$new_conf" <<EOF
$marker: a one-node cluster on $host.
# Rewritten on every start; stop with: bash scripts/slurm_local.sh stop
ClusterName=saresgs-local
SlurmctldHost=${host}(127.0.0.1)
SlurmUser=slurm
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
MailProg=/bin/true
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
SlurmdParameters=config_overrides
PropagatePrioProcess=1
ReturnToService=2
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=$ctld_pid
SlurmdPidFile=$slurmd_pid
SlurmctldLogFile=$log_dir/slurmctld.log
SlurmdLogFile=$log_dir/slurmd.log
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$real_mem State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
changed=0
if [ -f "$conf" ] && ! grep -qF "$marker" "$conf"; then
  echo "slurm_local: $conf exists and was not written by this script; not touching it" >&2
  exit 1
fi
if ! cmp -s "$new_conf" "$conf" 2>/dev/null; then
  install -d -m 0755 /etc/slurm
  install -m 0644 "$new_conf" "$conf"
  changed=1
  echo "slurm_local: wrote $conf ($host: $cpus CPUs, RealMemory=$real_mem MB)"
fi
install -d -o slurm -g slurm -m 0755 /var/spool/slurmctld "$log_dir"
install -d -o root -g root -m 0755 /var/spool/slurmd

# 4. The daemons. A configuration that changed under running daemons: restart them.
if [ "$changed" -eq 1 ]; then
  if live_pid "$ctld_pid" slurmctld >/dev/null || live_pid "$slurmd_pid" slurmd >/dev/null; then
    echo "slurm_local: configuration changed, restarting the daemons"
    stop_slurm
  fi
fi
# Without -D both fork into the background and write their pid files.
if ! live_pid "$ctld_pid" slurmctld >/dev/null; then
  echo "slurm_local: starting slurmctld"
  slurmctld || { echo "slurm_local: slurmctld failed to start" >&2; show_logs; exit 1; }
fi
if ! live_pid "$slurmd_pid" slurmd >/dev/null; then
  echo "slurm_local: starting slurmd"
  slurmd || { echo "slurm_local: slurmd failed to start" >&2; show_logs; exit 1; }
fi

# 5. Bounded wait for the node: idle (or busy with jobs already). A node left down or
# drained by an earlier run is resumed once.
resumed=0
state=""
for ((i = 0; i < timeout; i++)); do
  state="$(sinfo -h -N -n "$host" -o %T 2>/dev/null | head -n 1 || true)"
  case "$state" in
    idle | mixed | allocated | completing)
      echo "slurm_local: node $host is $state"
      sinfo
      exit 0
      ;;
    down | drained | draining)
      if [ "$resumed" -eq 0 ]; then
        scontrol update NodeName="$host" State=RESUME >/dev/null 2>&1 || true
        resumed=1
      fi
      ;;
  esac
  sleep 1
done
echo "slurm_local: node $host not up after ${timeout} s (state: '${state:-no answer}')" >&2
sinfo -N -l >&2 || true
show_logs
exit 1
