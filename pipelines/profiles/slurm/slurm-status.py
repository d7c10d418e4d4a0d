#!/usr/bin/env python3
"""Snakemake's cluster-status command for Slurm: prints running, success or
failed for a job id. Without it Snakemake waits for ever on a job the
scheduler killed (its script never reports back). Asks `sacct` where
accounting is kept, else `scontrol show job` (which knows a job until
MinJobAge after it ended)."""
import subprocess
import sys

job = sys.argv[1]
RUNNING = {"PENDING", "CONFIGURING", "RUNNING", "COMPLETING", "REQUEUED", "RESIZING", "SUSPENDED", "SIGNALING", "STAGE_OUT"}


def state_from_sacct():
    try:
        out = subprocess.run(["sacct", "-n", "-X", "-P", "-o", "State", "-j", job], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    lines = [l.strip() for l in out.stdout.splitlines() if l.strip()]
    return lines[0].split()[0] if out.returncode == 0 and lines else None


def state_from_scontrol():
    try:
        out = subprocess.run(["scontrol", "show", "job", "-o", job], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    for field in out.stdout.split():
        if field.startswith("JobState="):
            return field.split("=", 1)[1]
    return None


state = state_from_scontrol() or state_from_sacct()
if state is None:
    # Neither knows the job (purged, no accounting): its own outputs decide.
    print("success")
elif state in RUNNING:
    print("running")
elif state == "COMPLETED":
    print("success")
else:
    print("failed")
