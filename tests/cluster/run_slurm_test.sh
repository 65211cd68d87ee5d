#!/usr/bin/env bash
# The SLURM profile (workflow/profiles/slurm) on a real, throw-away, one-node SLURM cluster.
#
# Starts munged, slurmctld and slurmd on localhost from a configuration written to a temporary
# directory (accounting off, as on the cluster of the issue), runs the tiny config once on this
# machine and once through SLURM, compares every results/**/*.parquet table of the two runs
# (identical apart from timing columns), then makes a submitted simulation fail (on its own and in
# its group) and checks that Snakemake notices, stops within FAIL_LIMIT_S seconds and shows the
# job's own error. Prints both wall times and the number of SLURM jobs. Everything it starts is
# stopped by PID on exit and the temporary directory is removed (KEEP=1 keeps it).
#
# Needs root (slurmd launches jobs; missing Debian packages slurm-wlm and munge are installed with
# apt-get) and about five minutes on two cores. Not collected by pytest. Run from any clone:
#
#   tests/cluster/run_slurm_test.sh
#
# Environment: PYTHON (default <repo>/.venv/bin/python), CONFIG (default tests/data/tiny_config.yaml),
# FAIL_LIMIT_S (default 180), KEEP=1.
set -euo pipefail

REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
PYTHON=${PYTHON:-$REPO/.venv/bin/python}
CONFIG=$(realpath "${CONFIG:-$REPO/tests/data/tiny_config.yaml}")
FAIL_LIMIT_S=${FAIL_LIMIT_S:-180}
PROFILE=$REPO/workflow/profiles/slurm

say() { printf '[slurm-test] %s\n' "$*"; }
die() { say "FAIL: $*"; exit 1; }

# ---------------------------------------------------------------- packages
need=(munged slurmctld slurmd sbatch squeue sinfo scancel scontrol)
missing=()
for c in "${need[@]}"; do command -v "$c" >/dev/null || missing+=("$c"); done
if ((${#missing[@]})); then
    [[ $(id -u) == 0 ]] || die "missing ${missing[*]}; install slurm-wlm and munge (as root)"
    say "installing slurm-wlm and munge (missing: ${missing[*]})"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -q >/dev/null
    apt-get install -y -q slurm-wlm munge >/dev/null
fi
[[ $(id -u) == 0 ]] || die "run as root: slurmd starts the jobs"
"$PYTHON" -c "import snakemake_executor_plugin_slurm" 2>/dev/null ||
    die "$PYTHON has no snakemake-executor-plugin-slurm (pip install -e '.[cluster]')"

# ---------------------------------------------------------------- teardown (by PID only)
TMP=$(mktemp -d "${TMPDIR:-/tmp}/pe-slurm.XXXXXX")
chmod 755 "$TMP"
MUNGED_PID="" CTLD_PID="" SLURMD_PID="" CHILD_PID=""

stop_pid() {  # stop_pid PID NAME: TERM, up to 15 s, then KILL
    local pid=$1 name=$2 i
    [[ -n $pid ]] && kill -0 "$pid" 2>/dev/null || return 0
    kill -TERM "$pid" 2>/dev/null
    for ((i = 0; i < 150; i++)); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    if kill -0 "$pid" 2>/dev/null; then
        say "$name ($pid) ignored SIGTERM, sending SIGKILL"
        kill -KILL "$pid" 2>/dev/null
    fi
    wait "$pid" 2>/dev/null || true
}

cleanup() {
    local rc=$? i
    set +e
    trap - EXIT INT TERM
    stop_pid "$CHILD_PID" snakemake  # a run still going: Snakemake cancels its own SLURM jobs
    if [[ -n $CTLD_PID ]] && kill -0 "$CTLD_PID" 2>/dev/null; then
        scancel --quiet --full --user "$(id -un)" 2>/dev/null  # this cluster's jobs (SLURM_CONF)
        for ((i = 0; i < 30; i++)); do
            [[ -z $(squeue -h -t PD,R,CG -o %i 2>/dev/null) ]] && break
            sleep 1
        done
        # processes of job steps slurmd still knows of (none after a clean run)
        for pid in $(scontrol listpids 2>/dev/null | awk 'NR > 1 && $1 ~ /^[0-9]+$/ {print $1}'); do
            kill -KILL "$pid" 2>/dev/null
        done
    fi
    stop_pid "$SLURMD_PID" slurmd
    stop_pid "$CTLD_PID" slurmctld
    stop_pid "$MUNGED_PID" munged
    if [[ ${KEEP:-0} == 1 ]]; then
        say "kept $TMP"
    else
        rm -rf "$TMP"
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# ---------------------------------------------------------------- munge
mkdir -m 700 "$TMP/munge"
dd if=/dev/urandom of="$TMP/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$TMP/munge/munge.key"
munged --foreground --force --key-file="$TMP/munge/munge.key" --socket="$TMP/munge/munge.socket" \
    --pid-file="$TMP/munge/munged.pid" --log-file="$TMP/munge/munged.log" \
    --seed-file="$TMP/munge/munged.seed" >"$TMP/munge/stdout.log" 2>&1 &
MUNGED_PID=$!
for ((i = 0; i < 50; i++)); do [[ -S $TMP/munge/munge.socket ]] && break; sleep 0.1; done
[[ -S $TMP/munge/munge.socket ]] || { cat "$TMP/munge/munged.log" "$TMP/munge/stdout.log"; die "munged did not start"; }

# ---------------------------------------------------------------- slurm.conf: one node, this machine
NODE=$(hostname -s)
CPUS=$(nproc)
MEM_MB=$(awk '/^MemTotal:/ {printf "%d", $2 / 1024 * 0.95}' /proc/meminfo)
read -r CTLD_PORT SLURMD_PORT < <("$PYTHON" - <<'EOF'
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks:
    s.bind(("127.0.0.1", 0))
print(*(s.getsockname()[1] for s in socks))
EOF
)
S=$TMP/slurm
mkdir -p "$S/state" "$S/spool" "$TMP/bin"
: >"$S/plugstack.conf"
cat >"$S/slurm.conf" <<EOF
# Throw-away cluster of tests/cluster/run_slurm_test.sh
ClusterName=pe-test
SlurmctldHost=$NODE(127.0.0.1)
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$TMP/munge/munge.socket
StateSaveLocation=$S/state
SlurmdSpoolDir=$S/spool
SlurmctldPidFile=$S/slurmctld.pid
SlurmdPidFile=$S/slurmd.pid
SlurmctldLogFile=$S/slurmctld.log
SlurmdLogFile=$S/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
PlugStackConfig=$S/plugstack.conf
# no cgroups in a container: processes tracked through /proc, no task binding
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
# accounting off, as on the cluster of the issue: sacct and sacctmgr have nothing to ask
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
MpiDefault=none
ReturnToService=2
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM_MB State=UNKNOWN
PartitionName=test Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$S/slurm.conf  # every SLURM command of this script and of Snakemake reads this one

# The slurm-jobstep plugin (0.6.1) removes every SLURM_* variable but a few job ids from the
# environment of the `srun` it starts inside each job, SLURM_CONF included, so that srun would look
# for /etc/slurm/slurm.conf. A real cluster has that file (or a configless slurmd); this one puts
# an srun first on PATH that sets it back. Jobs inherit PATH through sbatch --export=ALL.
# The same srun makes a job fail on purpose when PE_SLURM_TEST_FAIL is set (the failure run below):
# the SLURM job then exits non-zero on the node, and only SLURM can tell the main process so.
cat >"$TMP/bin/srun" <<EOF
#!/bin/sh
if [ -n "\${PE_SLURM_TEST_FAIL:-}" ]; then
    echo "srun: job made to fail on purpose by run_slurm_test.sh (PE_SLURM_TEST_FAIL is set)" >&2
    exit 3
fi
SLURM_CONF='$SLURM_CONF' exec '$(command -v srun)' "\$@"
EOF
chmod 755 "$TMP/bin/srun"
export PATH=$TMP/bin:$PATH

slurmctld -D -c -f "$SLURM_CONF" >"$S/slurmctld.stdout" 2>&1 &
CTLD_PID=$!
slurmd -D -f "$SLURM_CONF" -N "$NODE" >"$S/slurmd.stdout" 2>&1 &
SLURMD_PID=$!
say "munged $MUNGED_PID, slurmctld $CTLD_PID, slurmd $SLURMD_PID (node $NODE: $CPUS CPUs, $MEM_MB MB; $S)"
state=""
for ((i = 0; i < 60; i++)); do
    state=$(sinfo -h -N -o %T 2>/dev/null || true)
    [[ $state == idle ]] && break
    kill -0 "$CTLD_PID" 2>/dev/null && kill -0 "$SLURMD_PID" 2>/dev/null || break
    sleep 1
done
if [[ $state != idle ]]; then
    tail -n 20 "$S/slurmctld.log" "$S/slurmd.log" "$S"/*.stdout 2>/dev/null
    die "node not idle after 60 s (state '$state')"
fi
say "node $NODE idle"

# ---------------------------------------------------------------- the two runs
ms() { date +%s%3N; }
secs() { awk -v ms="$1" 'BEGIN {printf "%.1f", ms / 1000}'; }

run_logged() {  # run_logged LOG CMD...: runs CMD in the background (so cleanup can stop it) and waits
    local log=$1 rc=0
    shift
    "$@" >"$log" 2>&1 &
    CHILD_PID=$!
    wait "$CHILD_PID" || rc=$?
    CHILD_PID=""
    return "$rc"
}

cd "$REPO"
say "local run: snakemake -j2 (default workflow profile) -> $TMP/local"
t0=$(ms)
run_logged "$TMP/local.log" "$PYTHON" -m snakemake -j2 -s "$REPO/Snakefile" -d "$TMP/local" \
    --configfile "$CONFIG" || { tail -n 40 "$TMP/local.log"; die "local run failed"; }
LOCAL_MS=$(($(ms) - t0))

say "SLURM run: snakemake --workflow-profile workflow/profiles/slurm -> $TMP/slurm"
t0=$(ms)
run_logged "$TMP/slurm.log" "$PYTHON" -m snakemake --workflow-profile "$PROFILE" -s "$REPO/Snakefile" \
    -d "$TMP/slurm" --configfile "$CONFIG" || { tail -n 60 "$TMP/slurm.log"; die "SLURM run failed"; }
SLURM_MS=$(($(ms) - t0))

grep -q "Using workflow specific profile $PROFILE" "$TMP/slurm.log" || die "the SLURM run did not use $PROFILE"
SUBMITTED=$(grep -c "has been submitted with SLURM jobid" "$TMP/slurm.log" || true)
ACCEPTED=$(grep -c "_slurm_rpc_submit_batch_job: JobId=" "$S/slurmctld.log" || true)
JOBS_DONE=$(grep -o "[0-9]* of [0-9]* steps (100%) done" "$TMP/slurm.log" | tail -n 1)

# ---------------------------------------------------------------- the tables agree
say "comparing results/**/*.parquet"
"$PYTHON" - "$TMP/local" "$TMP/slurm" <<'EOF'
import sys
from pathlib import Path

import pandas as pd

from particle_entropy.core.records import TIMING_COLUMNS

local, slurm = (Path(d) for d in sys.argv[1:3])
names = {p.relative_to(local) for p in (local / "results").rglob("*.parquet")}
other = {p.relative_to(slurm) for p in (slurm / "results").rglob("*.parquet")}
problems = [f"only in the local run: {n}" for n in sorted(names - other)]
problems += [f"only in the SLURM run: {n}" for n in sorted(other - names)]


def timing(column):
    """Measured time or memory of a process (records.TIMING_COLUMNS and what is derived from them)."""
    return column in TIMING_COLUMNS or column.startswith(("wall_", "peak_rss_mb"))


def without_timing(table):
    """The table without timing columns; in figure source data (x_name, x, y_name, y, ...), timing
    values are blanked on the rows that plot a timing quantity."""
    table = table.drop(columns=[c for c in table.columns if timing(c)])
    for axis, values in (("x", ["x"]), ("y", ["y", "y_std", "y_lo", "y_hi"])):
        if f"{axis}_name" in table:
            rows = table[f"{axis}_name"].map(timing)
            table.loc[rows, [c for c in values if c in table]] = float("nan")
            if rows.any():
                blanked.add(f"{axis} where {axis}_name is a timing column")
    return table


dropped, blanked = set(), set()
for name in sorted(names & other):
    a, b = pd.read_parquet(local / name), pd.read_parquet(slurm / name)
    dropped.update(c for c in [*a.columns, *b.columns] if timing(c))
    try:
        pd.testing.assert_frame_equal(without_timing(a), without_timing(b), check_exact=True)
    except AssertionError as err:
        problems.append(f"{name}: {str(err).strip().splitlines()[0]} ...")
print(f"{len(names & other)} tables compared; left out: {', '.join(sorted(dropped) + sorted(blanked))}")
for p in problems:
    print("MISMATCH", p)
sys.exit(1 if problems or not names else 0)
EOF

# ---------------------------------------------------------------- a failing job is noticed
# Runs for one simulation's table with PE_SLURM_TEST_FAIL set: every job they submit exits non-zero
# on the node (the srun above), whichever rule it runs. With accounting off, Snakemake can only
# learn that from squeue, and must stop, and show the job's own error (the srun's message, in
# SLURM's log of the job). Each runs in a copy of the SLURM run without that table, so that the
# simulation is the one job to run, whatever rule would come first in an empty folder. Two runs,
# for the two ways a job is submitted: on its own (`--groups` on the command line replaces the
# profile's groups, so the simulation is in none), where Snakemake lists SLURM's log after the
# job's own log, missing here (the copy has no logs/) and so ending Snakemake's report; and in its
# group, where SLURM's log comes first.
# (A broken particle_entropy first on PYTHONPATH would not do: common.smk puts workflow/lib first.)
TARGET=$(cd "$TMP/local" && find results/runs -name '*.parquet' | LC_ALL=C sort | awk 'NR == 1')  # awk reads all: no SIGPIPE
[[ -n $TARGET ]] || die "the local run made no results/runs table"

fail_run() {  # fail_run NAME [ARGS...]: a run for TARGET; sets FAIL_RC, FAIL_MS and FAILED_RULES
    local name=$1 dir=$TMP/fail-$1 log=$TMP/fail-$1.log t0
    shift
    cp -a "$TMP/slurm" "$dir"
    rm -rf "$dir/$TARGET" "$dir/$TARGET.sha256" "$dir/logs"  # no job log from the SLURM run
    say "failure run ($name): $TARGET in $dir, every SLURM job made to fail (limit ${FAIL_LIMIT_S} s)"
    t0=$(ms)
    FAIL_RC=0
    PE_SLURM_TEST_FAIL=1 run_logged "$log" timeout -k 30 "$((FAIL_LIMIT_S + 60))" \
        "$PYTHON" -m snakemake --workflow-profile "$PROFILE" -s "$REPO/Snakefile" -d "$dir" \
        "$TARGET" "$@" --configfile "$CONFIG" || FAIL_RC=$?
    FAIL_MS=$(($(ms) - t0))
    FAILED_RULES=$(grep -oE "Error in rule [A-Za-z0-9_]+" "$log" | awk '{print $4}' | sort -u | paste -sd, -)
    ((FAIL_RC != 0)) || die "the run with a failing job ($name) exited 0"
    ((FAIL_RC != 124)) || die "the run with a failing job ($name) did not stop within $((FAIL_LIMIT_S + 60)) s"
    ((FAIL_MS <= FAIL_LIMIT_S * 1000)) || die "the failing job ($name) was noticed after $(secs "$FAIL_MS") s"
    grep -q "has been submitted with SLURM jobid" "$log" || { tail -n 40 "$log"; die "$name: no job was submitted"; }
    [[ ,$FAILED_RULES, == *,simulate,* ]] ||
        { tail -n 40 "$log"; die "the failure run ($name) failed in '$FAILED_RULES', not in the simulation"; }
    grep -q "made to fail on purpose" "$log" ||
        { tail -n 40 "$log"; die "the failure run ($name) ended without showing the job's own error"; }
}

fail_run alone --groups fd_domain=sims  # any RULE=GROUP pair that leaves simulate out
! grep -q "Group job" "$TMP/fail-alone.log" || die "the failure run (alone) submitted a group job"
grep -qE "^Logfile logs/[^ ]+( not found\.|: empty file)$" "$TMP/fail-alone.log" ||
    die "the failure run (alone) did not show its job's own log as missing or empty, before SLURM's"
ALONE_RC=$FAIL_RC ALONE_MS=$FAIL_MS ALONE_RULES=$FAILED_RULES

fail_run group
grep -q "Group job" "$TMP/fail-group.log" || die "the failure run (group) submitted no group job"

FAILED=$(squeue -h --states=all -o "%i %T" | awk '$2 == "FAILED"' | wc -l)
((FAILED >= 2)) || die "$FAILED FAILED jobs in squeue after the two failure runs (expected 2 or more)"

# ---------------------------------------------------------------- report
say "local run:  $(secs "$LOCAL_MS") s"
say "SLURM run:  $(secs "$SLURM_MS") s, $SUBMITTED SLURM jobs submitted ($ACCEPTED accepted by slurmctld), ${JOBS_DONE:-?}"
say "failing job on its own ($ALONE_RULES) noticed, its error shown; Snakemake exited $ALONE_RC after $(secs "$ALONE_MS") s"
say "failing job in a group ($FAILED_RULES) noticed, its error shown; Snakemake exited $FAIL_RC after $(secs "$FAIL_MS") s"
say "PASS"
