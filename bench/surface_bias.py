#!/usr/bin/env python3
"""The bone surface's mean signed distance to the true head over a grid of
voxel sizes (in-plane x slice), on heads of all three phantom generators:
`articula phantom` (normal and osteoporotic bone, and osteoporotic bone in
slices 1 mm thicker than their spacing), bench/independent_phantom.py and
bench/third_phantom.py (a 1.2 mm and a thin cortex each). Each cell runs
`articula run` on one CT and scores its articular points against the truth
(mean signed distance, positive outside; RMS). Phantoms are cached in
WORK/phantoms; runs go to WORK/runs. Prints a markdown table (one row per head,
one column per voxel size) and writes WORK/surface_bias.json.

    python3 bench/surface_bias.py --bin build/bin --work WORK [--inplane 0.6,0.8,0.9,1.0]
        [--slices 1,2,3] [--cases articula-normal,third-thin] [--run-args '--edge-model steepest']
"""
import argparse
import csv
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
PY = os.environ.get("PYTHON", "/usr/bin/python3")  # Debian's, with numpy and scipy

# name -> (generator, options); the voxel size is added per cell (SLICE+1:
# the cell's slice spacing plus a millimetre).
CASES = {
    "articula-normal": ("articula", ["--seed", "11", "--radius", "23", "--gap", "2"]),
    "articula-osteoporotic": ("articula", ["--seed", "12", "--radius", "21", "--gap", "2", "--osteoporotic"]),
    "articula-thick-slices": ("articula", ["--seed", "13", "--radius", "24", "--gap", "2.5", "--osteoporotic",
                                           "--slice-thickness", "SLICE+1"]),
    "independent-normal": ("independent", ["side=right", "R=23", "gap=2", "seed=1"]),
    "independent-thin": ("independent", ["side=right", "R=25", "gap=2.5", "cortex=0.8", "cort_hu=800", "trab_hu=200",
                                         "seed=5"]),
    "third-normal": ("third", ["joint=hip", "side=right", "seed=101", "R=23", "gap=2.5", "cover=105", "excess=1.5"]),
    "third-thin": ("third", ["joint=hip", "side=left", "seed=109", "R=21", "gap=2", "cortex=0.8", "cort_hu=700",
                             "trab_hu=190", "tex=60", "noise=20"]),
}


def side_of(gen, opts):
    for o in opts:
        if o.startswith("side="):
            return o.split("=", 1)[1]
    return "right"


def make_phantom(gen, opts, spacing, folder):
    """Writes the CT (returns its path and the truth's path) unless cached
    with the same options."""
    sp = ",".join(f"{v:g}" for v in spacing)
    opts = [f"{spacing[2] + 1:g}" if o == "SLICE+1" else o for o in opts]
    stamp, said = f"{folder}/options.txt", " ".join([gen, sp, *opts])
    if os.path.exists(stamp) and open(stamp).read() != said:
        shutil.rmtree(folder)
    os.makedirs(folder, exist_ok=True)
    open(stamp, "w").write(said)
    if gen == "articula":
        ct, truth = f"{folder}/phantom.nii.gz", f"{folder}/truth.json"
        if not os.path.exists(truth):
            subprocess.run([f"{ARGS.bin}/articula", "phantom", "-o", folder, "--exact", "--no-dicom", "--force", "-q",
                            "--spacing", sp, *opts], check=True, stdout=subprocess.DEVNULL)
        return ct, truth
    base = f"{folder}/ct"
    if not os.path.exists(base + ".json"):
        script = "independent_phantom.py" if gen == "independent" else "third_phantom.py"
        subprocess.run([PY, f"{HERE}/{script}", f"out={base}", f"spacing={sp}", *opts], check=True,
                       stdout=subprocess.DEVNULL)
    return base + ".nii.gz", base + ".json"


def distances(gen, run, truth, side):
    """Each articular point's signed distance to the true head (mm, positive
    outside), with the share of its direction from the head's centre that
    runs across the slices (z^2 of the unit direction)."""
    t = json.load(open(truth))
    if gen == "articula":
        subprocess.run([f"{ARGS.bin}/bench-score-head", truth, side, f"{run}/points.ply"], check=True,
                       capture_output=True, text=True, env=dict(os.environ, ARTICULA_SCORE_POINTS=f"{run}/score.csv"))
        c = next(h for h in t["hips"] if h["side"] == side)["head_center_mm"]
        out = []
        for r in csv.DictReader(open(f"{run}/score.csv")):
            d = [float(r[k]) - c[i] for i, k in enumerate("xyz")]
            out.append((float(r["signed_mm"]), d[2] ** 2 / sum(v * v for v in d)))
        return out
    points = [[float(r[k]) for k in ("x_mm", "y_mm", "z_mm")] for r in csv.DictReader(open(f"{run}/errors/errors.csv"))]
    if gen == "independent":  # an axis-aligned ellipsoid
        c, rad, axes = t["head_center_mm"], t["radii_mm"], [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    else:
        h = next(h for h in t["heads"] if h["side"] == side)
        c, rad, axes = h["head_center_mm"], h["radii_mm"], h["axes_lps_columns"]
    out = []
    for p in points:
        d = [p[i] - c[i] for i in range(3)]
        local = [sum(d[r] * axes[r][k] for r in range(3)) for k in range(3)]  # (p - c) A
        n = math.sqrt(sum(v * v for v in local))
        q = math.sqrt(sum((local[k] / rad[k]) ** 2 for k in range(3)))
        out.append((n - n / q, d[2] ** 2 / sum(v * v for v in d)))  # radial distance to the ellipsoid
    return out


def main():
    global ARGS
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("--work", required=True)
    ap.add_argument("--inplane", default="0.6,0.8,0.9,1.0")
    ap.add_argument("--slices", default="1,2,3")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--run-args", default="")
    ap.add_argument("--threads", default="1")
    ARGS = ap.parse_args()
    ARGS.bin = os.path.abspath(ARGS.bin)
    inplane = [float(v) for v in ARGS.inplane.split(",")]
    slices = [float(v) for v in ARGS.slices.split(",")]
    cells = [(a, b) for b in slices for a in inplane]
    rows = []
    for name in ARGS.cases.split(","):
        gen, opts = CASES[name]
        side = side_of(gen, opts)
        joint = "shoulder" if "joint=shoulder" in opts else "hip"
        for a, b in cells:
            tag = f"{name}-{a:g}x{a:g}x{b:g}"
            ct, truth = make_phantom(gen, opts, (a, a, b), f"{ARGS.work}/phantoms/{tag}")
            run = f"{ARGS.work}/runs/{tag}"
            # A NIfTI file holds no slice thickness: given as a user would.
            thickness = json.load(open(truth)).get("slice_thickness_mm")
            given = ["--slice-thickness", f"{thickness:g}"] if thickness else []
            t0 = time.time()
            r = subprocess.run([f"{ARGS.bin}/articula", "run", "-i", ct, "-o", run, "--joint", joint, "--side", side,
                                "--threads", ARGS.threads, "--force", "-q", *given, *shlex.split(ARGS.run_args)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            row = dict(case=name, inplane=a, slice=b, exit=r.returncode, seconds=round(time.time() - t0, 1))
            if r.returncode == 0:
                scored = distances(gen, run, truth, side)
                d = [v for v, _ in scored]
                row["mean_signed_mm"] = sum(d) / len(d)
                row["rms_mm"] = math.sqrt(sum(v * v for v in d) / len(d))
                for part, keep in (("within", lambda z: z < 0.5), ("across", lambda z: z >= 0.5)):
                    ds = [v for v, z in scored if keep(z)]
                    row[f"mean_signed_{part}_slices_mm"] = sum(ds) / len(ds) if ds else None
                edges = json.load(open(f"{run}/bone.vtp.json"))["ct_edges"]
                row["edge_model"] = edges.get("edge_model")
                row["point_spread_mm"] = [edges.get("point_spread_mm"), edges.get("slice_point_spread_mm")]
                row["point_spread_kind"] = edges.get("point_spread_applied")
            else:
                row["message"] = (r.stderr.strip().splitlines() or [""])[-1][:160]
            rows.append(row)
            print(json.dumps(row), file=sys.stderr, flush=True)
    json.dump(rows, open(f"{ARGS.work}/surface_bias.json", "w"), indent=1)
    head = "| head | " + " | ".join(f"{a:g} x {a:g} x {b:g}" for a, b in cells) + " |"
    print(head)
    print("|---|" + "---|" * len(cells))
    for name in ARGS.cases.split(","):
        cellsOf = {(r["inplane"], r["slice"]): r for r in rows if r["case"] == name}
        text = []
        for c in cells:
            r = cellsOf.get(c)
            text.append("" if r is None else f"{r['mean_signed_mm']:+.3f}" if r["exit"] == 0 else f"exit {r['exit']}")
        print(f"| {name} | " + " | ".join(text) + " |")
    scored = [r["mean_signed_mm"] for r in rows if r["exit"] == 0]
    if scored:
        print(f"\nheads scored: {len(scored)} of {len(rows)}; mean signed {min(scored):+.3f} to {max(scored):+.3f} mm; "
              f"within 0.05 mm: {sum(abs(v) <= 0.05 for v in scored)}")


if __name__ == "__main__":
    main()
