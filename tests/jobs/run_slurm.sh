#!/usr/bin/env bash
# A render farm on a real scheduler: starts a one-node Slurm on localhost
# (munged with a key made here, slurmctld and slurmd in the foreground, no
# systemd, no cgroup plugins, every file in the scratch directory, ports
# found free), runs the Slurm recipe of man/pfx.1 DISTRIBUTED RENDERING
# as written there (the job script, `sbatch --wait render.sh`, then
# `pfx assemble`; /shared becomes the scratch directory), and compares
# every assembled frame with a one-process render byte for byte. The
# README's copy of the recipe must say the same commands.
#
# Skips (exit 77) only when not root or when Slurm or munge is not
# installed (Debian's slurm-wlm and munge: ./install-deps --test). Daemons
# that do not start, or a node that never becomes idle, are a failure with
# their logs printed. The daemons this test started are stopped on exit,
# whatever happened.
#
#   bash run_slurm.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" slurm "$@"
cd "$work" || exit 2
export PATH=$pfx_dir:$PATH:/usr/sbin:/sbin

if [ "$(id -u)" -ne 0 ]; then
    echo "SKIP: not root (slurmd and slurmctld run here as root, SlurmUser=root)"
    exit 77
fi
for c in munged munge unmunge slurmctld slurmd sbatch sinfo squeue scontrol scancel; do
    if ! command -v "$c" >/dev/null; then
        echo "SKIP: no '$c' (Debian's slurm-wlm and munge: ./install-deps --test)"
        exit 77
    fi
done

# ---- the daemons, stopped by the EXIT trap
daemons=() # "name pid"
slurm_up=0
stop_daemons() {
    local entry pid i alive
    # Cancel whatever is left on this private cluster, so that no task of
    # it runs on in the scratch directory.
    if [ "$slurm_up" = 1 ]; then
        timeout 10 scancel -u "$(id -un)" 2>/dev/null
        for i in $(seq 50); do
            [ -z "$(timeout 5 squeue -h 2>/dev/null)" ] && break
            sleep 0.2
        done
    fi
    # slurmd first, so that it does not lose its controller; munged last.
    for ((i = ${#daemons[@]} - 1; i >= 0; i--)); do
        kill "${daemons[i]#* }" 2>/dev/null
    done
    for i in $(seq 50); do
        alive=0
        for entry in "${daemons[@]}"; do
            kill -0 "${entry#* }" 2>/dev/null && alive=1
        done
        [ "$alive" = 0 ] && break
        sleep 0.2
    done
    for entry in "${daemons[@]}"; do
        pid=${entry#* }
        kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null
        wait "$pid" 2>/dev/null
    done
    daemons=()
}
trap 'stop_daemons; rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# start NAME CMD...: a daemon in the foreground, its output in NAME.out.
start() {
    local name=$1
    shift
    "$@" </dev/null >"$work/$name.out" 2>&1 &
    daemons+=("$name $!")
}
# give_up PROBLEM: fails with every daemon's state and log, and ends.
give_up() {
    local entry f
    fail "$1"
    for entry in "${daemons[@]}"; do
        kill -0 "${entry#* }" 2>/dev/null && echo "  ${entry% *}: running" || echo "  ${entry% *}: not running"
    done
    for f in "$work"/*.out "$work"/node.log; do
        [ -s "$f" ] || continue
        echo "  --- ${f##*/} (last 30 lines)"
        tail -n 30 "$f" | sed 's/^/  | /'
    done
    summary
    exit 1
}

host=$(hostname -s)
# The node as slurmd sees it (CPUs, boards, sockets, cores, threads), with a
# small RealMemory: a node that claims more than slurmd finds is drained.
node=$(slurmd -C | head -n 1 | sed -n 's/^NodeName=[^ ]* \(CPUs=.*\) RealMemory=.*/\1 /p')
[ -n "$node" ] || give_up "slurmd -C says nothing usable: $(slurmd -C 2>&1 | head -n 1)"
read -r ctld_port slurmd_port < <("$py" -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s:
    x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')

mkdir -p state spool shared
dd if=/dev/urandom of=munge.key bs=1024 count=1 2>/dev/null && chmod 600 munge.key
cat >slurm.conf <<EOF
ClusterName=pfxtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge.sock
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
# FIFO: a queued array task starts when one ends, not at the next backfill
# pass (every 30 s).
SchedulerType=sched/builtin
# sbatch --wait polls every 2 s, stretching to 32 s while it is below
# MinJobAge/2: with 10, it polls at most every 8 s.
MinJobAge=10
NodeName=$host NodeAddr=127.0.0.1 ${node}RealMemory=100 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$work/slurm.conf

start munged munged -F -f --key-file="$work/munge.key" --socket="$work/munge.sock" \
    --pid-file="$work/munged.pid" --log-file="$work/munged.log" --seed-file="$work/munged.seed"
for i in $(seq 50); do
    [ -S munge.sock ] && break
    sleep 0.1
done
munge -n -S "$work/munge.sock" 2>munge.err | unmunge -S "$work/munge.sock" >/dev/null 2>>munge.err ||
    give_up "munged does not answer on its socket: $(tail -n 2 munge.err)"
pass "munged answers"

slurm_up=1
start slurmctld slurmctld -D -f "$SLURM_CONF"
start slurmd slurmd -D -f "$SLURM_CONF" -N "$host"
# Bounded: a node is idle within seconds or something is wrong.
state=
for i in $(seq 120); do
    for entry in "${daemons[@]}"; do
        kill -0 "${entry#* }" 2>/dev/null || give_up "${entry% *} exited"
    done
    state=$(timeout 5 sinfo -h -N -n "$host" -o %t 2>/dev/null)
    [ "$state" = idle ] && break
    sleep 0.5
done
if [ "$state" != idle ]; then
    timeout 5 scontrol show node "$host" >node.log 2>&1
    give_up "node '$host' is '${state:-unknown}' after 60 s, not idle"
fi
pass "slurmctld and slurmd up, node '$host' idle"

# ---- the recipe, from the man page
cp -r "$src/effects" effects
"$py" - "$src/man/pfx.1" "$src/README.md" "$work" <<'PY' >recipe.txt
import re, sys
man, readme, work = open(sys.argv[1]).read(), open(sys.argv[2]).read(), sys.argv[3]
def unroff(t):
    return t.replace("\\-", "-").replace("\\e", "\\")
section = man[man.index(".SH DISTRIBUTED RENDERING"):]
section = section[section.index("Slurm,"):]
blocks = re.findall(r"^\.EX\n(.*?)^\.EE\n", section, re.S | re.M)
script, assemble = unroff(blocks[0]), unroff(blocks[1]).strip()
lines = [l for l in script.splitlines() if not l.startswith("#")]
render = re.sub(r"\s*\\\n\s*", " ", "\n".join(lines)).strip()
# The README's copy: the two lines after "# Slurm".
after = readme[readme.index("# Slurm"):].splitlines()
bad = []
if after[1].strip() != render:
    bad.append("README says '%s', man/pfx.1 '%s'" % (after[1].strip(), render))
if after[2].strip() != assemble:
    bad.append("README says '%s', man/pfx.1 '%s'" % (after[2].strip(), assemble))
print(("FAIL the README's Slurm recipe is the man page's: " + "; ".join(bad)) if bad else
      "ok   the README's Slurm recipe is the man page's")
open(work + "/effects/render.sh", "w").write(script.replace("/shared", work + "/shared"))
open(work + "/assemble.sh", "w").write(assemble.replace("/shared", work + "/shared") + "\n")
PY
tally "$(cat recipe.txt)"
grep -q -- '--array=0-7' effects/render.sh && grep -q 'SLURM_ARRAY_TASK_ID' effects/render.sh ||
    give_up "no Slurm job script found in man/pfx.1: $(cat effects/render.sh)"

begin "sbatch --wait render.sh: 8 array tasks, each a slice"
cd effects || exit 2
timeout 300 sbatch --wait render.sh >sbatch.out 2>sbatch.err
st=$?
cd "$work" || exit 2
[ "$st" -eq 124 ] && flunk "not done after 300 s"
[ "$st" -eq 0 ] || flunk "sbatch exit status $st: $(tail -n 3 effects/sbatch.err)"
for f in effects/slurm-*.out; do
    [ -s "$f" ] && flunk "$f: $(head -c 300 "$f")"
done
n=$(ls shared/fire/fire.slice-*-of-0008.manifest.json 2>/dev/null | wc -l)
[ "$n" -eq 8 ] || flunk "$n slice manifests, not 8"
end
[ "$check_ok" = 1 ] || give_up "the job array did not finish"

begin "pfx assemble, as the recipe says"
bash assemble.sh >assemble.out 2>assemble.err || flunk "assemble failed: $(cat assemble.err)"
end

begin "every frame equals the one-process render's, byte for byte"
(cd effects && "$pfx" render fire.yaml -o "$work/one" -q) || flunk "the one-process render failed"
n=0
for f in one/fire_*.png; do
    n=$((n + 1))
    cmp -s "$f" "shared/fire-all/${f#one/}" || flunk "shared/fire-all/${f#one/} differs"
done
[ "$n" -gt 1 ] || flunk "the one-process render has $n frames"
m=$(ls shared/fire-all/fire_*.png | wc -l)
[ "$m" -eq "$n" ] || flunk "$m assembled frames, $n rendered in one process"
key() { "$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["bake_key"])' "$1"; }
[ "$(key one/fire.manifest.json)" = "$(key shared/fire-all/fire.manifest.json)" ] ||
    flunk "the assembled manifest's bake key is not the one-process render's"
end

summary
