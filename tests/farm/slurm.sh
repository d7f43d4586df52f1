#!/bin/sh
# make test-farm: deploy/slurm's templates run by a live Slurm, a one-node
# cluster on this machine.  Installs slurm-wlm and munge when they are
# missing (as root, apt-get), writes a slurm.conf for this machine into a
# temporary folder, starts munged, slurmctld and slurmd there as processes
# of its own (no systemd, no /etc), submits with deploy/slurm/submit.sh and
# checks:
#   - a frame range over 3 array tasks: every frame written, byte for byte
#     the frames of a local `obscura batch` of the same range;
#   - a range with an input frame missing: that task FAILED with obscura's
#     exit code 3 (`scontrol show job`: no slurmdbd, so no sacct), the
#     others COMPLETED; the frame put back, `scontrol requeue` completes it;
#   - a static bake over 3 shards + the afterok merge = the unsharded bake,
#     and a dynamic bake over 2 shards + merge = the unsharded model;
#   - a long task cancelled (scancel) mid-range: every frame under its name
#     whole (= the local frame), no temporary file left.
# It prints the jobs' table (before the requeue), cancels whatever is left, stops each
# daemon by its own pid and checks that nothing it started still runs.
# Skipped (exit 0, "SKIPPED") only where Slurm cannot run: not root, or
# slurm-wlm not installable.
#
#   BUILD=build tests/farm/slurm.sh      (make test-farm)
set -u
BUILD=${BUILD:-build}
OBSCURA=$(cd "$(dirname "${OBSCURA:-$BUILD/obscura}")" && pwd)/$(basename "${OBSCURA:-$BUILD/obscura}")
ROOT=$(pwd)
DATA=$ROOT/tests/data
SUBMIT=$ROOT/deploy/slurm/submit.sh
PATH=$PATH:/usr/sbin:/sbin
START=$(date +%s)
pass=0
failed=0
ok() { pass=$((pass + 1)); echo "  ok   $*"; }
bad() { failed=$((failed + 1)); echo "  FAIL $*"; }
check() { if eval "$2"; then ok "$1"; else bad "$1"; fi; }
skip() { echo "test-farm: SKIPPED: $*"; exit 0; }
# until SECONDS COMMAND: polls COMMAND every 0.5 s, at most SECONDS; 1 on timeout
until_ok() {
    n=$(($1 * 2)); shift
    while ! eval "$1"; do n=$((n - 1)); [ "$n" -gt 0 ] || return 1; sleep 0.5; done
}

echo "test-farm: Slurm one-node cluster, obscura $OBSCURA"
[ -x "$OBSCURA" ] || { echo "test-farm: no $OBSCURA (run make first)"; exit 1; }
have() { for c in slurmctld slurmd sbatch squeue scontrol scancel munged; do
    command -v $c >/dev/null 2>&1 || return 1; done; }
[ "$(id -u)" -eq 0 ] || skip "slurmd must run as root to start jobs (run as root)"
if ! have; then
    command -v apt-get >/dev/null 2>&1 || skip "slurm-wlm is not installed and there is no apt-get"
    echo "test-farm: installing slurm-wlm and munge"
    { apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q \
        --no-install-recommends slurm-wlm munge; } >/tmp/obscura-farm-apt.log 2>&1 ||
        { tail -5 /tmp/obscura-farm-apt.log; skip "apt-get could not install slurm-wlm munge"; }
    have || skip "slurm-wlm installed but its commands are missing"
fi

T=$(mktemp -d /tmp/obscura-farm.XXXXXX)
chmod 755 "$T"
MUNGED="" CTLD="" SLURMD=""
export SLURM_CONF="$T/slurm.conf"
# the daemons (and their slurmstepd) carry OBSCURA_FARM_DAEMON=$T in their
# environment, the jobs OBSCURA_FARM_TEST=$T (sbatch --export=ALL) and a
# SLURM_JOB_ID: the last check finds what is left by them
export OBSCURA_FARM_TEST="$T"
ours() {
    for e in /proc/[0-9]*/environ; do
        p=${e#/proc/}; p=${p%/environ}
        [ "$p" = $$ ] && continue
        env=$({ tr '\0' '\n' <"$e"; } 2>/dev/null)
        case $env in
        *"OBSCURA_FARM_DAEMON=$T"*) echo "$p" ;;
        *"OBSCURA_FARM_TEST=$T"*SLURM_JOB_ID=* | *SLURM_JOB_ID=*"OBSCURA_FARM_TEST=$T"*) echo "$p" ;;
        esac
    done
}
stop() {
    [ -n "$1" ] || return 0
    kill -TERM "$1" 2>/dev/null || return 0
    n=20
    while kill -0 "$1" 2>/dev/null && [ $n -gt 0 ]; do sleep 0.5; n=$((n - 1)); done
    kill -KILL "$1" 2>/dev/null
    wait "$1" 2>/dev/null
}
cleanup() {
    trap - EXIT INT TERM
    if [ -n "$CTLD" ] && kill -0 "$CTLD" 2>/dev/null; then
        # the jobs first: a running job's slurmstepd outlives slurmd
        # shellcheck disable=SC2046
        scancel --quiet $(squeue -h -o %A 2>/dev/null | sort -u) 2>/dev/null
        until_ok 30 '[ -z "$(squeue -h 2>/dev/null)" ]'
    fi
    stop "$SLURMD"
    stop "$CTLD"
    stop "$MUNGED"
    left=$(ours)
    if [ -n "$left" ]; then
        echo "test-farm: still running after the daemons stopped, killed: $left"
        for p in $left; do kill -KILL "$p" 2>/dev/null; done
        failed=$((failed + 1))
    fi
    if [ "$failed" -ne 0 ]; then
        for l in "$T"/*.log "$T"/logs/*.out; do
            [ -f "$l" ] && { echo "--- $l"; tail -15 "$l"; }
        done
    fi
    rm -rf "$T"
    echo "test-farm: $pass passed, $failed failed, $(($(date +%s) - START)) s"
    [ "$failed" -eq 0 ]
}
trap 'cleanup; exit $?' EXIT
trap 'exit 1' INT TERM

# ---- the cluster --------------------------------------------------------------
host=$(hostname -s)
node=$(slurmd -C 2>/dev/null | sed -n 's/^NodeName=[^ ]* \(.*\)/\1/p' | sed 's/ *$//')
[ -n "$node" ] || node="CPUs=$(nproc)"
ports=$(python3 -c 'import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')
set -- $ports
mkdir -p "$T/munge" "$T/state" "$T/spool" "$T/logs"
chmod 700 "$T/munge"
dd if=/dev/urandom of="$T/munge/munge.key" bs=1024 count=1 2>/dev/null
chmod 400 "$T/munge/munge.key"
cat >"$SLURM_CONF" <<EOF
# written by tests/farm/slurm.sh: one node, this machine, everything in $T
ClusterName=obscurafarm
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$1
SlurmdPort=$2
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
# cred_expire: a requeued job waits it out before it starts again (120 s by default)
AuthInfo=socket=$T/munge/munge.sock,cred_expire=10
CredType=cred/munge
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
SchedulerParameters=bf_interval=1
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MpiDefault=none
ReturnToService=2
KillWait=5
MinJobAge=900
MessageTimeout=20
NodeName=$host NodeAddr=127.0.0.1 $node State=UNKNOWN
PartitionName=farm Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF

OBSCURA_FARM_DAEMON=$T munged -F -f --key-file="$T/munge/munge.key" --socket="$T/munge/munge.sock" \
    --pid-file="$T/munge/munged.pid" --log-file="$T/munged.log" --seed-file="$T/munge/seed" \
    >"$T/munged.out" 2>&1 &
MUNGED=$!
until_ok 15 '[ -S "$T/munge/munge.sock" ]' && ok "munged started (pid $MUNGED)" ||
    { bad "munged did not start"; cat "$T/munged.out"; exit 1; }
OBSCURA_FARM_DAEMON=$T slurmctld -D -i -f "$SLURM_CONF" >"$T/slurmctld.out" 2>&1 &
CTLD=$!
until_ok 30 'scontrol ping 2>/dev/null | grep -q UP' && ok "slurmctld started (pid $CTLD, port $1)" ||
    { bad "slurmctld did not start"; exit 1; }
OBSCURA_FARM_DAEMON=$T slurmd -D -f "$SLURM_CONF" -N "$host" >"$T/slurmd.out" 2>&1 &
SLURMD=$!
until_ok 60 'scontrol show node "$host" 2>/dev/null | grep -q "State=IDLE"' &&
    ok "slurmd started (pid $SLURMD), node $host idle: $node" ||
    { bad "node $host not idle"; scontrol show node "$host"; exit 1; }

# ---- the work -----------------------------------------------------------------
mkdir -p "$T/in" "$T/inm" "$T/inc" "$T/ref" "$T/bake"
for f in $(seq 1 12); do ln -s "$DATA/room_small.exr" "$T/in/room.$(printf %04d "$f").exr"; done
for f in 1 2 3 4 5 6 8; do ln -s "$DATA/room_small.exr" "$T/inm/room.$(printf %04d "$f").exr"; done
for f in $(seq 1 400); do ln -s "$DATA/room_small.exr" "$T/inc/room.$(printf %04d "$f").exr"; done
CAM=$DATA/room_small.camera.json
FIX=$DATA/levels/aalborg_cut.acc
BAKE_TRACE="--rays 16"
DYN_TRACE="--rays 32 --max-regions 8"

# One CPU and a little memory per task: both cores of this machine busy.
SB="--chdir=$T/logs --cpus-per-task=1 --mem=500M --time=10"
export OBSCURA OBSCURA_CAMERA="$CAM"
# the long task first, so that it starts at once and is cancelled mid-range
cjob=$(OBSCURA_INPUT="$T/inc/room.####.exr" OBSCURA_OUTPUT="$T/outc/ao.####.exr" \
    "$SUBMIT" frames 1 400 400 $SB --job-name=cancelled)
fjob=$(OBSCURA_INPUT="$T/in/room.####.exr" OBSCURA_OUTPUT="$T/out/ao.####.exr" \
    "$SUBMIT" frames 1 12 4 $SB)
mjob=$(OBSCURA_INPUT="$T/inm/room.####.exr" OBSCURA_OUTPUT="$T/outm/ao.####.exr" \
    "$SUBMIT" frames 1 8 4 $SB --job-name=missing)
bjobs=$(PARTS="$T/bake/parts" TRACE_ARGS=$BAKE_TRACE "$SUBMIT" bake "$FIX" "$T/bake/merged.glb" 3 $SB)
djobs=$(PARTS="$T/bake/dparts" TRACE_ARGS=$DYN_TRACE "$SUBMIT" bake-dynamic "$FIX" "$T/bake/dmerged.json" 2 $SB)
ALL=$(echo $cjob $fjob $mjob $bjobs $djobs)
set -- $ALL
check "7 jobs submitted: frames, cancelled, missing, bake and bake-dynamic (shards, merge): $ALL" "[ $# = 7 ]"

# the references, locally, while Slurm runs
"$OBSCURA" batch "$T/in/room.####.exr" --frames 1-12 -o "$T/ref/ao.####.exr" --camera "$CAM" -q 2>"$T/ref.log"
"$OBSCURA" bake "$FIX" -o "$T/bake/whole.glb" $BAKE_TRACE -q 2>>"$T/ref.log"
"$OBSCURA" bake-dynamic "$FIX" -o "$T/bake/dwhole.json" $DYN_TRACE -q 2>>"$T/ref.log"
check "local references: 12 frames, the unsharded bake and model" \
    "[ \$(ls $T/ref | wc -l) = 12 ] && [ -s $T/bake/whole.glb ] && [ -s $T/bake/dwhole.json ]"

# scancel once the long task has written a few frames
until_ok 120 '[ $(ls "$T/outc" 2>/dev/null | wc -l) -ge 3 ]' || bad "the long task wrote no frames"
[ -n "${FARM_PAUSE:-}" ] && sleep "$FARM_PAUSE"
scancel "$cjob"
until_ok 60 '[ -z "$(squeue -h -j $cjob 2>/dev/null)" ]' || bad "the cancelled task did not end"

jobs_done() { [ -z "$(squeue -h -j "$(echo $ALL | tr ' ' ,)" 2>/dev/null)" ]; }
until_ok 180 jobs_done && ok "every job left the queue ($(($(date +%s) - START)) s in)" ||
    { bad "jobs still queued after 180 s"; squeue; }

# table: every job's tasks as scontrol shows them (no slurmdbd here, so no sacct)
table() {
    printf '%-12s %-7s %-28s %-11s %-9s %s\n' TASK JOBID NAME STATE EXITCODE ELAPSED
    for j in $ALL; do
        scontrol -o show job "$j" 2>/dev/null | tr ' ' '\n' | awk -F= '
            /^JobId=/ { id = $2 } /^ArrayJobId=/ { aj = $2 } /^ArrayTaskId=/ { at = $2 }
            /^JobName=/ { nm = $2 } /^JobState=/ { st = $2 } /^ExitCode=/ { ec = $2 }
            /^RunTime=/ { printf "%-12s %-7s %-28s %-11s %-9s %s\n", (aj ? aj "_" at : id), id, nm, st, ec, $2; aj = at = "" }'
    done | sort -V -u
}
# field JOB KEY: KEY=value from scontrol's one-line record(s) of JOB
field() { scontrol -o show job "$1" 2>/dev/null | tr ' ' '\n' | sed -n "s/^$2=//p"; }

echo "-- the jobs, before the requeue (scontrol show job)"
table
echo "-- a frame range over 3 array tasks"
check "3 tasks, each COMPLETED with exit 0:0" "[ \"\$(field $fjob JobState | sort | uniq -c | tr -s ' ')\" = ' 3 COMPLETED' ] && [ \"\$(field $fjob ExitCode | sort -u)\" = 0:0 ]"
same=0
for f in $(seq -w 1 12); do cmp -s "$T/ref/ao.00$f.exr" "$T/out/ao.00$f.exr" && same=$((same + 1)); done
check "12 frames written, each byte for byte the local batch's ($same same)" "[ $same = 12 ] && [ \$(ls $T/out | wc -l) = 12 ]"

echo "-- an input frame missing (7 of 1-8)"
check "task 0 (frames 1-4) COMPLETED, 0:0" "[ \"\$(field ${mjob}_0 JobState) \$(field ${mjob}_0 ExitCode)\" = 'COMPLETED 0:0' ]"
check "task 1 (frames 5-8) FAILED with obscura's exit code 3 (3:0)" \
    "[ \"\$(field ${mjob}_1 JobState) \$(field ${mjob}_1 ExitCode)\" = 'FAILED 3:0' ]"
check "... and still wrote the chunk's other frames (5, 6, 8; not 7)" "[ -e $T/outm/ao.0005.exr ] && [ -e $T/outm/ao.0008.exr ] && [ ! -e $T/outm/ao.0007.exr ]"
ln -s "$DATA/room_small.exr" "$T/inm/room.0007.exr"
check "the frame put back, scontrol requeue of the failed task" "scontrol requeue ${mjob}_1 2>$T/requeue.log"
# a requeued job starts after cred_expire (10 s here, 120 s by default)
until_ok 120 '[ "$(field ${mjob}_1 JobState)" = COMPLETED ]' &&
    ok "the requeued task COMPLETED, exit $(field "${mjob}_1" ExitCode)" ||
    bad "the requeued task: $(field "${mjob}_1" JobState) $(field "${mjob}_1" Reason)"
same=0
for f in 1 2 3 4 5 6 7 8; do cmp -s "$T/ref/ao.0001.exr" "$T/outm/ao.000$f.exr" && same=$((same + 1)); done
check "frames 1-8 all written and whole ($same of 8 = the local frame)" "[ $same = 8 ]"

echo "-- bakes over shards, merged after afterok"
set -- $bjobs
check "bake: 3 shard tasks and the merge COMPLETED" \
    "[ \"\$(field $1 JobState | sort -u) \$(field $2 JobState)\" = 'COMPLETED COMPLETED' ] && [ \$(field $1 JobState | wc -l) = 3 ]"
check "bake: the merge ran after the shards (afterok)" \
    "[ \"\$(field $2 StartTime)\" \\> \"\$(field $1 EndTime | sort | tail -1)\" ] || [ \"\$(field $2 StartTime)\" = \"\$(field $1 EndTime | sort | tail -1)\" ]"
check "bake: merged .glb = the unsharded bake, byte for byte" "cmp -s $T/bake/whole.glb $T/bake/merged.glb"
set -- $djobs
check "bake-dynamic: 2 shard tasks and the merge COMPLETED" \
    "[ \"\$(field $1 JobState | sort -u) \$(field $2 JobState)\" = 'COMPLETED COMPLETED' ] && [ \$(field $1 JobState | wc -l) = 2 ]"
check "bake-dynamic: merged model = the unsharded model, byte for byte" "cmp -s $T/bake/dwhole.json $T/bake/dmerged.json"
check "no merge folder left beside the outputs" "[ -z \"\$(ls -A $T/bake | grep '^\.')\" ]"

echo "-- a task cancelled mid-range (scancel)"
n=$(ls "$T/outc" | wc -l)
check "CANCELLED, with $n of 400 frames written" "[ \"\$(field $cjob JobState)\" = CANCELLED ] && [ $n -lt 400 ]"
whole=0
for f in "$T"/outc/ao.*.exr; do cmp -s "$T/ref/ao.0001.exr" "$f" && whole=$((whole + 1)); done
check "every frame under its name whole ($whole of $n = the local frame)" "[ $whole = $n ]"
check "no temporary file left (.ao.NNNN.exr.PID.tmp)" "[ -z \"\$(ls -A $T/outc | grep -v '^ao\.[0-9]*\.exr$')\" ]"

exit 0
