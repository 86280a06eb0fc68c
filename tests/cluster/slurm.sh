#!/bin/bash
# A real cluster: the Slurm job-array example of docs/datasets.md (Sharding) run on a
# single-node Slurm cluster, and the merged dataset compared byte for byte with the unsharded one.
#
# Usage, as root:  tests/cluster/slurm.sh [HILSIM]     (HILSIM: default the release binary, built
# and found through cargo: .ci/hilsim-binary --release)
#
# Installs Debian's slurm-wlm and munge when slurmctld is missing. Everything else lives in a
# temporary directory: munge's key, socket and seed, slurm.conf (SLURM_CONF), the state, spool
# and log directories, the daemons' pid files, the datasets. Ports are picked free, so the
# system's own munged/Slurm (if any) are left alone. Every daemon started here is stopped and the
# directory removed on any exit.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
HILSIM=${1:-$(bash "$ROOT/.ci/hilsim-binary" --release)}
SCENARIO=$ROOT/scenarios/landmarks-5.toml
RUNS=8
TASKS=4
WAIT=60 # seconds, for each bounded wait

die() {
    echo "slurm: FAIL: $*" >&2
    exit 1
}

[ "$(id -u)" = 0 ] || die "run me as root (I install packages and start munged, slurmctld, slurmd)"
[ -x "$HILSIM" ] || die "no hilsim binary at $HILSIM (cargo build --release --bin hilsim, or pass its path)"
HILSIM=$(realpath "$HILSIM")
[ -f "$SCENARIO" ] || die "no scenario $SCENARIO"

# 1. The packages.
if ! command -v slurmctld >/dev/null; then
    echo "slurm: installing slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi
for c in munged mungekey slurmctld slurmd sbatch squeue sinfo scontrol; do
    command -v "$c" >/dev/null || die "$c not found after installing slurm-wlm and munge"
done

T=$(mktemp -d /tmp/hilsim-slurm.XXXXXX)
chmod 0711 "$T" # root only writes; munged wants its socket reachable
PIDS=() # pid files of the daemons started here
JOBS=   # the jobs submitted here

show_logs() {
    for f in "$T"/log/*.log; do
        [ -s "$f" ] || continue
        echo "---- $f (last 30 lines)" >&2
        tail -n 30 "$f" >&2
    done
}

# Whether process $1 runs (a zombie does not: daemons reparented to a PID 1 that reaps nothing).
running() {
    local st
    st=$(sed 's/.*) //' "/proc/$1/stat" 2>/dev/null) || return 1
    [ "${st%% *}" != Z ]
}

cleanup() {
    local rc=$?
    set +e
    [ "$rc" = 0 ] || show_logs
    # Jobs still queued or running (an interruption): cancelled while slurmctld is there.
    if [ -n "$JOBS" ]; then
        scancel $JOBS 2>/dev/null
        for _ in $(seq 40); do
            [ -z "$(squeue -h -j "${JOBS// /,}" -o %i 2>/dev/null)" ] && break
            sleep 0.25
        done
    fi
    # Daemons in reverse order of their start: slurmd, slurmctld, munged.
    local i pid
    for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
        pid=$(cat "${PIDS[$i]}" 2>/dev/null) || continue
        [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null || continue
        for _ in $(seq 100); do running "$pid" || break; sleep 0.1; done
        if running "$pid"; then
            echo "slurm: pid $pid (${PIDS[$i]##*/}) ignored SIGTERM for 10 s: killed" >&2
            kill -KILL "$pid" 2>/dev/null
        fi
    done
    rm -rf "$T"
    exit "$rc"
}
trap cleanup EXIT
trap 'echo "slurm: FAIL: interrupted" >&2; exit 130' INT
trap 'echo "slurm: FAIL: terminated" >&2; exit 143' TERM

# A free TCP port on this machine, different from those in $*.
free_port() {
    local p
    for _ in $(seq 50); do
        p=$((20000 + RANDOM % 20000))
        case " $* " in *" $p "*) continue ;; esac
        if ! (echo >"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then
            echo "$p"
            return
        fi
    done
    die "no free TCP port found"
}

mkdir -p -m 0711 "$T"/munge && mkdir -p "$T"/log "$T"/run "$T"/state "$T"/spool "$T"/out

# 2a. munge: its own key, socket, pid, seed and log file.
mungekey --create --keyfile="$T/munge/munge.key" 2>/dev/null \
    || dd if=/dev/urandom of="$T/munge/munge.key" bs=1024 count=1 status=none
chmod 0400 "$T/munge/munge.key"
MUNGE_SOCKET=$T/munge/munge.socket
munged --force --key-file="$T/munge/munge.key" --socket="$MUNGE_SOCKET" \
    --pid-file="$T/run/munged.pid" --seed-file="$T/munge/munged.seed" \
    --log-file="$T/log/munged.log" \
    || die "munged did not start"
PIDS+=("$T/run/munged.pid")
for _ in $(seq $((WAIT * 10))); do [ -S "$MUNGE_SOCKET" ] && break; sleep 0.1; done
[ -S "$MUNGE_SOCKET" ] || die "munged's socket $MUNGE_SOCKET did not appear in $WAIT s"
munge --socket="$MUNGE_SOCKET" -n </dev/null | unmunge --socket="$MUNGE_SOCKET" >/dev/null \
    || die "munge cannot encode and decode a credential with its own key"

# 2b. slurm.conf: one node, this machine, for a container without systemd or cgroups.
CTLD_PORT=$(free_port)
SLURMD_PORT=$(free_port "$CTLD_PORT")
CPUS=$(nproc)
export SLURM_CONF=$T/slurm.conf
cat >"$SLURM_CONF" <<EOF
ClusterName=hilsim-ci
SlurmctldHost=localhost
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$MUNGE_SOCKET
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/run/slurmctld.pid
SlurmdPidFile=$T/run/slurmd.pid
SlurmctldLogFile=$T/log/slurmctld.log
SlurmdLogFile=$T/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=600
MailProg=/bin/true
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=500 State=UNKNOWN
# OverSubscribe: the $TASKS tasks of the array run at once even on a machine of fewer cores.
PartitionName=ci Nodes=localhost Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:$TASKS
EOF

# 2c. The daemons, as root, in the background.
slurmctld -f "$SLURM_CONF" -c || die "slurmctld did not start"
PIDS+=("$T/run/slurmctld.pid")
slurmd -f "$SLURM_CONF" -N localhost || die "slurmd did not start"
PIDS+=("$T/run/slurmd.pid")

state=
for _ in $(seq $((WAIT * 2))); do
    state=$(sinfo -h -n localhost -o %T 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.5
done
[ "$state" = idle ] || die "the node is not idle after $WAIT s (sinfo: '${state:-no answer}')"

# Waits until none of the jobs $* is pending or running.
wait_jobs() {
    local left
    for _ in $(seq $((WAIT * 4))); do
        # squeue failing (slurmctld busy) is no answer: asked again.
        if left=$(squeue -h -j "$(IFS=,; echo "$*")" -o %i 2>/dev/null) && [ -z "$left" ]; then
            return
        fi
        sleep 0.25
    done
    squeue -j "$(IFS=,; echo "$*")" >&2 || true
    die "jobs $* not done after $WAIT s"
}

# The final state and exit code of job $1 (every task, for an array): "COMPLETED 0:0" lines.
job_states() {
    scontrol -o show job "$1" | sed -E 's/.*JobState=([A-Z_]+).* ExitCode=([0-9:]+).*/\1 \2/'
}

# 3. The example of docs/datasets.md: a job array, one task per shard, into one fresh shared directory;
# then the merge, submitted to run after the array.
DATA=$T/sharded
cat >"$T/dataset.sbatch" <<EOF
#!/bin/bash
#SBATCH --array=1-$TASKS
#SBATCH --cpus-per-task=1
"$HILSIM" dataset "$SCENARIO" --runs $RUNS --out "$DATA" \\
    --vary robot.start.y=-0.2..0.2 --jobs "\$SLURM_CPUS_PER_TASK" \\
    --shard "\$SLURM_ARRAY_TASK_ID/\$SLURM_ARRAY_TASK_COUNT"
EOF
ARRAY=$(sbatch --parsable --chdir="$T" --output="$T/out/shard-%a.out" "$T/dataset.sbatch") \
    || die "sbatch of the job array failed"
JOBS=$ARRAY
MERGE=$(sbatch --parsable --chdir="$T" --output="$T/out/merge.out" \
    --dependency="afterany:$ARRAY" --wrap "'$HILSIM' dataset merge --out '$DATA'") \
    || die "sbatch of the merge failed"
JOBS="$ARRAY $MERGE"
wait_jobs "$ARRAY" "$MERGE"

report_out() {
    for f in "$T"/out/*.out; do
        echo "---- $f" >&2
        cat "$f" >&2
    done
}
states=$(job_states "$ARRAY")
n=$(grep -c . <<<"$states")
[ "$n" = "$TASKS" ] || { report_out; die "the array $ARRAY has $n tasks, not $TASKS"; }
grep -qv '^COMPLETED 0:0$' <<<"$states" \
    && { report_out; die "a task of the array $ARRAY did not succeed: $(tr '\n' ' ' <<<"$states")"; }
[ "$(job_states "$MERGE")" = "COMPLETED 0:0" ] \
    || { report_out; die "the merge job $MERGE did not succeed: $(job_states "$MERGE")"; }
for i in $(seq "$TASKS"); do
    grep -q "^dataset $DATA: " "$T/out/shard-$i.out" || { report_out; die "shard $i printed no summary"; }
done

# 4. The same dataset unsharded, and the comparison: every file, hidden ones too, nothing
# excluded (a dataset holds no wall times: dataset.toml has its parameters, manifest.csv the runs').
PLAIN=$T/unsharded
"$HILSIM" dataset "$SCENARIO" --runs $RUNS --out "$PLAIN" --vary robot.start.y=-0.2..0.2 \
    >"$T/out/unsharded.out" 2>&1 || { cat "$T/out/unsharded.out" >&2; die "the unsharded dataset failed"; }
made=$(find "$DATA" -mindepth 1 -maxdepth 1 -type d -name 'run-*' | wc -l)
[ "$made" = "$RUNS" ] || die "the merged dataset holds $made runs, not $RUNS"
diff -r "$DATA" "$PLAIN" >&2 || die "the merged dataset differs from the unsharded one"
[ "$(cd "$DATA" && find . | LC_ALL=C sort)" = "$(cd "$PLAIN" && find . | LC_ALL=C sort)" ] \
    || die "the merged and unsharded datasets hold different files"

echo "slurm: $TASKS-task job array merged equals the unsharded dataset ($RUNS runs)"
