#!/usr/bin/env bash
# The Snakemake workflow on a real Slurm cluster, with the shipped Slurm
# profile: a single-node cluster (munge, slurmctld and slurmd on loopback
# ports, their keys, state and logs in this test's folder) runs a study of
# two small phantoms, the left hip of both and a CT cut short on purpose.
# Every stage job goes through sbatch (the scheduler's job completion log
# lists them), the failed subject is reported with its log, the study tables
# are those of `articula batch` on the same manifest, a second invocation
# submits nothing, and the cluster is stopped whatever happens.
# Skipped (exit 77) without Slurm's and munge's programs, Snakemake, or root.
# labels: scheduler
# Alone: its jobs wait on the scheduler and on Snakemake's start in each job
# (about 50 s of CPU over 36 s): beside another test it took 77 s.
# run: alone
source "$(dirname "$0")/common.bash"
src=${ARTICULA_SOURCE:?}
for program in munged slurmctld slurmd sbatch scontrol sinfo snakemake; do
  command -v "$program" > /dev/null || { echo "skipped: $program is not installed (scripts/install-deps.sh --all)"; exit 77; }
done
[ "$(id -u)" -eq 0 ] || { echo "skipped: slurmd runs jobs as root here; not root"; exit 77; }

cluster=$tmp/cluster
mkdir -p "$cluster/munge" "$cluster/state" "$cluster/spool"
chmod 700 "$cluster/munge"
stop_cluster() {
  for daemon in slurmd slurmctld; do
    [ -f "$cluster/$daemon.pid" ] && kill "$(cat "$cluster/$daemon.pid")" 2> /dev/null || true
  done
  munged --stop --socket="$cluster/munge/socket" > /dev/null 2>&1 || true
}
trap stop_cluster EXIT
head -c 1024 /dev/urandom > "$cluster/munge/key"
chmod 400 "$cluster/munge/key"
munged --force --key-file="$cluster/munge/key" --socket="$cluster/munge/socket" --pid-file="$cluster/munge/pid" \
  --log-file="$cluster/munge/log" --seed-file="$cluster/munge/seed"
read -r controller_port node_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*(x.getsockname()[1] for x in s))')
host=$(hostname -s)
cat > "$cluster/slurm.conf" <<CONF
ClusterName=articula
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$controller_port
SlurmdPort=$node_port
AuthType=auth/munge
AuthInfo=socket=$cluster/munge/socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$cluster/state
SlurmdSpoolDir=$cluster/spool
SlurmctldPidFile=$cluster/slurmctld.pid
SlurmdPidFile=$cluster/slurmd.pid
SlurmctldLogFile=$cluster/slurmctld.log
SlurmdLogFile=$cluster/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$cluster/jobs.log
MpiDefault=none
SchedulerType=sched/builtin
# Start a job when it is submitted: by default sbatch's jobs wait for the next
# scheduling pass, up to 3 s, six times in a subject's chain.
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MinJobAge=600
# Eight CPUs declared whatever the machine has (config_overrides): a stage job
# here waits on the scheduler and Snakemake's start far more than it computes.
SlurmdParameters=config_overrides
NodeName=node1 NodeHostname=$host NodeAddr=127.0.0.1 CPUs=8 RealMemory=16000 State=UNKNOWN
PartitionName=articula Nodes=node1 Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$cluster/slurm.conf
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF" -N node1
for _ in $(seq 100); do
  sinfo -h -o %t 2> /dev/null | grep -q idle && break
  sleep 0.1
done
sinfo -h -o %t | grep -q idle || { tail "$cluster"/*.log >&2; fail "the test cluster's node did not come up"; }

# Two subjects at coarse voxels, their edges on the steepest fall (the
# blurred-cortex model would triple the jobs' time; the test is of the
# scheduler): the left hip of both, and a CT cut short (its segment stage
# fails). Each stage job spends about 2 s of CPU in Snakemake's own start on
# this machine's 2 cores, so a third subject would cost a third more.
"$bin/articula" phantom -o "$tmp/p3" --seed 3 --spacing 1.5,1.5,2 --side left --no-dicom --quiet
head -c 20000 "$tmp/p3/phantom.nii.gz" > "$tmp/cut.nii.gz"
cat > "$tmp/study.csv" <<CSV
subject,input,joint,side,edge_model
p3,p3/phantom.nii.gz,hip,left,steepest
cut,cut.nii.gz,hip,right,steepest
CSV
snake() {
  # One thread a stage, so that the node runs up to eight jobs at once; CI=true:
  # Snakemake's cluster executor then polls its jobs every second, not every 10.
  CI=true snakemake -s "$src/pipelines/Snakefile" --profile "$src/pipelines/profiles/slurm" --latency-wait 5 \
    --set-threads segment=1 mesh=1 fit=1 errors=1 \
    --config manifest="$tmp/study.csv" study="$tmp/slurm" bin="$bin" > "$tmp/snake$1.log" 2>&1 ||
    { tail -40 "$tmp/snake$1.log" >&2; tail -5 "$cluster/slurmctld.log" >&2; fail "snakemake on Slurm (run $1)"; }
}
# The reference batch runs beside the workflow: a stage job spends most of
# its time waiting on the scheduler and Snakemake's start, not computing.
"$bin/articula" batch "$tmp/study.csv" -o "$tmp/batch" --quiet & reference=$!
snake 1
wait "$reference" || true

python3 - "$tmp" "$cluster/jobs.log" <<'PY'
import csv, json, sys
tmp, jobs_log = sys.argv[1:3]
jobs = [dict(f.split("=", 1) for f in line.split() if "=" in f) for line in open(jobs_log)]
stages = ["segment", "mesh", "sample", "fit", "errors", "report"]
names = sorted(j["Name"] for j in jobs)
want = sorted(f"articula-{stage}-{s}" for stage in stages for s in ["p3", "cut"])
assert names == want, ("the scheduler's jobs", names, want)
assert all(j["JobState"] == "COMPLETED" for j in jobs), [j for j in jobs if j["JobState"] != "COMPLETED"]
def rows(path, keep):
    with open(path, newline="") as f:
        return [{k: r[k] for k in keep if k in r} for r in csv.DictReader(f)]
status = rows(f"{tmp}/slurm/study_status.csv", ["subject", "status", "exit_code", "message"])
print("snakemake on slurm:", len(jobs), "jobs;", status)
assert status == rows(f"{tmp}/batch/study_status.csv", ["subject", "status", "exit_code", "message"]), status
failed = json.load(open(f"{tmp}/slurm/subjects/cut/status.json"))
assert failed["status"] == "failed" and failed["exit_code"] == 3, failed
assert "cut.nii.gz" in failed["message"], failed
for name in ["study.csv", "study_summary.csv"]:
    assert open(f"{tmp}/slurm/{name}").read() == open(f"{tmp}/batch/{name}").read(), name
PY
grep -q "articula: error: " "$tmp/slurm/subjects/cut/logs/segment.log" || fail "the failed stage's log holds no error"
ls "$tmp"/slurm/subjects/p3/logs/segment.log.slurm-*.txt > /dev/null || fail "no Slurm log beside the stage's"
jobs_before=$(wc -l < "$cluster/jobs.log")
snake 2
[ "$(wc -l < "$cluster/jobs.log")" -eq "$jobs_before" ] || fail "a second invocation submitted jobs again"
grep -q "Nothing to be done" "$tmp/snake2.log" || fail "a second invocation: $(tail -5 "$tmp/snake2.log")"
echo "slurm: ok"
