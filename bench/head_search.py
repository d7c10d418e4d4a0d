#!/usr/bin/env python3
"""The head search of two builds side by side on N seeded random phantoms
(voxels 0.5 x 0.5 x 0.6 to 1.5 x 1.5 x 3 mm, noise 15-70 HU, gaps 1.2-4 mm,
radii 17-30 mm, both sides; some with both hips, osteoporotic bone, a soft
or sharp kernel, a screw or a stem, a fovea): `articula-segment` of each,
the search's centre error to the true head centre and its radius, or its
refusal. Prints one line per phantom (SAME where both builds agree to the
printed digits) and the counts. Phantoms are cached in WORK.

    python3 bench/head_search.py OLD_BIN NEW_BIN WORK [N=40]
"""
import json
import os
import random
import subprocess
import sys


def options(rnd, i):
    spacing = rnd.choice([(0.5, 0.5, 0.6), (0.7, 0.7, 1.5), (0.9, 0.9, 2.5), (1, 1, 3), (1.2, 1.2, 3),
                          (0.6, 0.6, 1), (1.5, 1.5, 3)])
    opts = ["--seed", str(500 + i), "--spacing", ",".join(map(str, spacing)), "--side", rnd.choice(["right", "left"]),
            "--gap", f"{rnd.uniform(1.2, 4):.2f}", "--noise", f"{rnd.uniform(15, 70):.0f}"]
    if rnd.random() < 0.3:
        opts.append("--both-hips")
    if rnd.random() < 0.25:
        opts.append("--osteoporotic")
    if rnd.random() < 0.2:
        opts += ["--kernel", rnd.choice(["soft", "sharp"])]
    if rnd.random() < 0.2:
        opts += ["--metal", rnd.choice(["screw", "stem"])]
    if rnd.random() < 0.2:
        opts.append("--fovea")
    return opts


def search(bin_dir, folder, side, tag, truth):
    out = f"{folder}/{tag}.nii.gz"
    r = subprocess.run([f"{bin_dir}/articula-segment", "-i", f"{folder}/phantom.nii.gz", "-o", out, "--joint", "hip",
                        "--side", side, "-q", "--force", "--threads", "1"], capture_output=True, text=True)
    if r.returncode != 0:
        return f"refused ({r.returncode})"
    summary = json.load(open(out + ".json"))
    error = sum((a - b) ** 2 for a, b in zip(summary["head_center_mm"], truth["head_center_mm"])) ** 0.5
    return f"{error:.2f} mm off, radius {summary['search_radius_mm']:.2f} mm, by {summary['head_found_by']}"


def main():
    old, new, work = sys.argv[1:4]
    n = int(sys.argv[4]) if len(sys.argv) > 4 else 40
    rnd = random.Random(2026)
    same = 0
    for i in range(n):
        opts = options(rnd, i)
        folder = f"{work}/p{i}"
        if not os.path.exists(f"{folder}/truth.json"):
            subprocess.run([f"{new}/articula", "phantom", "-o", folder, "--radius-range", "17,30", "--no-dicom", "-q"]
                           + opts, check=True)
        truth = json.load(open(f"{folder}/truth.json"))
        side = opts[opts.index("--side") + 1]
        before, after = search(old, folder, side, "old", truth), search(new, folder, side, "new", truth)
        same += before == after
        print(f"{i:3d} {' '.join(opts)}: {before} | {after}" + ("  SAME" if before == after else ""), flush=True)
    print(f"{same} of {n} the same")


if __name__ == "__main__":
    main()
