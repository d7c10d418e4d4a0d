#!/usr/bin/env python3
"""Robustness benchmark: `articula run` over a matrix of phantom heads, each
scored against its truth. See bench/robustness.sh for the usage."""
import argparse
import concurrent.futures as futures
import json
import os
import random
import statistics
import subprocess
import sys
import time

MODELS = ["sphere", "ellipsoid", "superellipsoid", "ovoid", "superovoid"]
# Spacing groups (mm): the 0.6-0.8 group cycles through its members.
GROUPS = [
    ("0.6-0.8", [(0.6, 0.6, 0.6), (0.7, 0.7, 0.7), (0.8, 0.8, 0.8), (0.7, 0.7, 0.8)]),
    ("1x1x1.25", [(1.0, 1.0, 1.25)]),
    ("1x1x2", [(1.0, 1.0, 2.0)]),
    ("1.5x1.5x3", [(1.5, 1.5, 3.0)]),
]
# The fresh set (--fresh): other seeds, voxels and radii, kept apart from the
# matrix above while a method is chosen and scored once to confirm it.
FRESH_GROUPS = [
    ("0.5-0.9", [(0.5, 0.5, 0.5), (0.9, 0.9, 0.9), (0.6, 0.6, 1.0), (0.8, 0.8, 0.6)]),
    ("0.9x0.9x1.5", [(0.9, 0.9, 1.5)]),
    ("0.8x0.8x2.5", [(0.8, 0.8, 2.5)]),
    ("1.2x1.2x3", [(1.2, 1.2, 3.0)]),
]
# An exact fit within this of the true surface's points stands for the true
# model: a shape drawn within it of a simpler model is that model to any data.
SAME_SHAPE_MM = 0.01


def matrix(quick, fresh=False):
    """CT phantoms, each with the sides to run: 12 single-hip CTs and 2
    both-hips CTs (both sides run) per spacing group, 64 heads in all."""
    cts = []
    base = 7000 if fresh else 0  # seeds of the fresh set lie apart from the matrix's
    for g, (group, spacings) in enumerate(FRESH_GROUPS if fresh else GROUPS):
        for i in range(12):
            rng = random.Random(base + 1000 * g + i)
            side = "right" if (i + fresh) % 2 == 0 else "left"
            shift = 2 * g + 1 if fresh else g  # which model each CT of the group has
            cts.append(dict(
                id=f"{'f' if fresh else 'g'}{g}-{i:02d}", group=group, spacing=spacings[i % len(spacings)],
                seed=base + 100 * g + i + 1, model=MODELS[(i + shift) % 5], sides=[side], both=False,
                dicom=i % 3 == 0, ras=i % 4 in (1, 2),
                gap=rng.choice([1.5, 2.0, 2.5, 3.0, 4.0, 5.0]),
                radius=round(rng.uniform(15, 32) if fresh else rng.uniform(17, 30), 1),
                socket="spherical" if rng.random() < 0.3 else "congruent",
                osteoporotic=rng.random() < 0.3, fovea=rng.random() < 0.5))
        for b in range(2):
            rng = random.Random(base + 1000 * g + 50 + b)
            # In the first group a coarse member: a wide field of view.
            sp = spacings[0] if g else spacings[1] if fresh else spacings[-1]
            cts.append(dict(
                id=f"{'f' if fresh else 'g'}{g}-pelvis{b}", group=group, spacing=sp, seed=base + 100 * g + 50 + b, model=None,
                sides=["right", "left"], both=True, dicom=b == 1, ras=b == 1,
                gap=rng.choice([1.5, 2.0, 2.5, 3.0, 4.0, 5.0]), radius=None,
                socket="congruent", osteoporotic=b == 1, fovea=True))
    if quick:
        keep = {"g0-00", "g1-00", "g2-00", "g3-00", "g1-pelvis0", "g3-pelvis1"}
        cts = [c for c in cts if c["id"] in keep]
    return cts


# The models each model contains (itself aside).
CONTAINED = {"sphere": set(), "ellipsoid": {"sphere"}, "superellipsoid": {"sphere", "ellipsoid"},
             "ovoid": {"sphere", "ellipsoid"}, "superovoid": {"sphere", "ellipsoid", "superellipsoid", "ovoid"}}


def shape_model(bin_dir, exact_points, fits_json):
    """The simplest model whose fit to the true surface's points at the run's
    points (exact data) lies within SAME_SHAPE_MM RMS: the model the truth
    is to any data (a drawn ellipsoid of radii within 0.1 % is a sphere);
    and how far the truth departs from every model that does not contain
    that one (the least RMS of their exact fits, mm; None for a sphere):
    what the data must resolve for the selection to tell it."""
    subprocess.run([f"{bin_dir}/articula", "fit", "-i", exact_points, "-o", fits_json, "--force", "-q", "--threads", "1"],
                   check=True)
    fits = json.load(open(fits_json))
    rms = {f["model"]: (f["geometric_objective_mm2"] / fits["n_points"]) ** 0.5 for f in fits["models"]}
    model = next((m for m in MODELS if rms[m] <= SAME_SHAPE_MM), MODELS[-1])
    others = [rms[m] for m in MODELS if m != model and model not in CONTAINED[m]]
    return model, min(others) if others else None


def resolvable(rows):
    """The selection on heads whose true shape departs from every model not
    containing it by at least the points' own error (RMS to the true
    surface), and on the rest."""
    done = [r for r in rows if r["exit"] == 0 and r.get("departure_mm") is not None]
    parts = []
    for name, group in (("departing by at least the points' RMS error", [r for r in done if r["departure_mm"] >= r["rms_mm"]]),
                        ("by less", [r for r in done if r["departure_mm"] < r["rms_mm"]])):
        right = sum(r.get("selected") == r.get("shape_model") for r in group)
        parts.append(f"{name}: {right} of {len(group)} right")
    return "Heads other than spheres, " + "; ".join(parts) + "."


def run_ct(ct, bin_dir, work, run_args=()):
    """Makes the phantom, runs each side and scores it; returns one row per head."""
    d = os.path.join(work, ct["id"])
    cmd = [f"{bin_dir}/articula", "phantom", "-o", f"{d}/ct", "--seed", str(ct["seed"]), "--exact", "--force", "-q",
           "--spacing", ",".join(map(str, ct["spacing"])), "--gap", str(ct["gap"]), "--socket", ct["socket"],
           "--side", ct["sides"][0]]
    if ct["model"]:
        cmd += ["--model", ct["model"]]
    cmd += ["--radius", str(ct["radius"])] if ct["radius"] else ["--radius-range", "17,30"]
    cmd += ["--both-hips"] * ct["both"] + ["--ras"] * ct["ras"] + ["--osteoporotic"] * ct["osteoporotic"]
    cmd += ["--fovea"] * ct["fovea"] + ([] if ct["dicom"] else ["--no-dicom"])
    t0 = time.time()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    phantom_s = time.time() - t0
    truth = json.load(open(f"{d}/ct/truth.json"))
    source = f"{d}/ct/dicom" if ct["dicom"] else f"{d}/ct/phantom.nii.gz"
    rows = []
    for side in ct["sides"]:
        out = f"{d}/run-{side}"
        t0 = time.time()
        r = subprocess.run([f"{bin_dir}/articula", "run", "-i", source, "-o", out, "--joint", "hip", "--side", side,
                            "--force", "-q", "--threads", "1", *run_args], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                           text=True)
        head = next(h for h in truth["hips"] if h["side"] == side)
        row = dict(ct, side=side, exit=r.returncode, seconds=round(time.time() - t0, 1), phantom_s=round(phantom_s, 1),
                   true_model=head["model"], true_radius=round(sum(head["radii_mm"]) / 3, 1),
                   message=(r.stderr.strip().splitlines() or [""])[-1][:160])
        if r.returncode == 0:
            exact = f"{d}/true-points-{side}.csv"
            s = subprocess.run([f"{bin_dir}/bench-score-head", f"{d}/ct/truth.json", side, f"{out}/points.ply",
                                f"{out}/results.json"], check=True, capture_output=True, text=True,
                               env=dict(os.environ, ARTICULA_SCORE_TRUE_POINTS=exact))
            row.update(json.loads(s.stdout))
            row["shape_model"], row["departure_mm"] = shape_model(bin_dir, exact, f"{d}/true-fits-{side}.json")
            results = json.load(open(f"{out}/results.json"))
            row["selected"] = results.get("selected_model")
            row["qc"] = results.get("qc", {}).get("status", "")
            limit = 0.5 * min(ct["spacing"][0], ct["spacing"][1])
            ok = row["rms_mm"] <= limit and row["share_within_1p5_mm"] >= 0.95
            # Wrong with a warning of the head or its surface (not only of the
            # side) in results.json and on stderr is flagged, not silent.
            warned = any(c["status"] == "warn" and c["name"] != "side_verified"
                         for c in results.get("qc", {}).get("checks", []))
            row["verdict"] = "correct" if ok else "wrong, warned" if warned else "SILENTLY WRONG"
        else:
            row["verdict"] = "refused"
        rows.append(row)
    return rows


def fmt(v, spec=".2f"):
    return "" if v is None else format(v, spec)


def table(rows):
    lines = ["| spacing group | heads | correct | refused | wrong, warned | silently wrong | median centre error (mm) | "
             "median RMS (mm) | median mean signed (mm) |", "|---|---|---|---|---|---|---|---|---|"]
    for group, _ in GROUPS + FRESH_GROUPS + [("all", None)]:
        g = [r for r in rows if group in ("all", r["group"])]
        if not g:
            continue
        share = lambda v: f"{100.0 * sum(r['verdict'] == v for r in g) / len(g):.0f} %"
        scored = [r for r in g if r["exit"] == 0]
        med = lambda k: fmt(statistics.median([r[k] for r in scored])) if scored else ""
        lines.append(f"| {group} | {len(g)} | {share('correct')} | {share('refused')} | {share('wrong, warned')} | {share('SILENTLY WRONG')} | "
                     f"{med('centre_error_mm')} | {med('rms_mm')} | {med('mean_signed_mm')} |")
    lines += ["", "| case | side | spacing (mm) | input | model | radius (mm) | gap (mm) | socket | bone | fovea | "
              "verdict | exit | centre error (mm) | RMS (mm) | mean signed (mm) | within 1.5 mm | run (s) | message |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        inp = ("DICOM" if r["dicom"] else "NIfTI") + (" RAS" if r["ras"] else " LPS")
        lines.append(
            f"| {r['id']} | {r['side']} | {'x'.join(map(str, r['spacing']))} | {inp} | {r['true_model']} | "
            f"{r['true_radius']} | {r['gap']} | {r['socket']}{' (both hips)' if r['both'] else ''} | "
            f"{'osteoporotic' if r['osteoporotic'] else 'normal'} | {'yes' if r['fovea'] else 'no'} | "
            f"{r['verdict']} | {r['exit']} | {fmt(r.get('centre_error_mm'))} | {fmt(r.get('rms_mm'), '.3f')} | "
            f"{fmt(r.get('mean_signed_mm'), '.3f')} | {fmt(100 * r['share_within_1p5_mm'], '.0f') + ' %' if 'share_within_1p5_mm' in r else ''} | "
            f"{r['seconds']} | {r['message'] if r['exit'] else ''} |")
    return "\n".join(lines)


def confusion(rows, key="true_model"):
    """The selected model against the true one (key "shape_model": the
    simplest model the true surface is), over the heads run to the end."""
    lines = ["| true \\ selected | " + " | ".join(MODELS) + " | heads | correct |",
             "|---|" + "---|" * (len(MODELS) + 2)]
    for true in MODELS:
        g = [r for r in rows if r["exit"] == 0 and r.get(key) == true]
        counts = [sum(r.get("selected") == m for r in g) for m in MODELS]
        lines.append(f"| {true} | " + " | ".join(map(str, counts)) + f" | {len(g)} | "
                     f"{100.0 * counts[MODELS.index(true)] / len(g) if g else 0:.0f} % |")
    done = [r for r in rows if r["exit"] == 0]
    right = sum(r.get("selected") == r.get(key) for r in done)
    by_group = ", ".join(f"{g}: {sum(r.get('selected') == r.get(key) for r in done if r['group'] == g)} of "
                         f"{sum(r['group'] == g for r in done)}" for g in dict.fromkeys(r["group"] for r in done))
    lines += ["", f"{right} of {len(done)} right ({by_group})."]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("--work", required=True)
    ap.add_argument("-j", type=int, default=2)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--fresh", action="store_true", help="the fresh set: other seeds, voxels and radii")
    ap.add_argument("--ids", default="", help="comma-separated case ids to run (default: the whole matrix)")
    ap.add_argument("--run-args", default="", help="extra arguments for articula run, e.g. '--edge-model cortex'")
    args = ap.parse_args()
    bin_dir = os.path.abspath(args.bin)
    os.makedirs(args.work, exist_ok=True)
    cts = matrix(args.quick, args.fresh)
    if args.ids:
        cts = [c for c in cts if c["id"] in args.ids.split(",")]
    # Largest first, so that the slowest CTs do not finish last.
    order = sorted(cts, key=lambda c: (-len(c["sides"]) * (1.0 / (c["spacing"][0] ** 2 * c["spacing"][2]))))
    t0 = time.time()
    rows = []
    with futures.ThreadPoolExecutor(max_workers=args.j) as pool:
        for done in futures.as_completed([pool.submit(run_ct, c, bin_dir, args.work, args.run_args.split()) for c in order]):
            for r in done.result():
                rows.append(r)
                print(f"{r['id']} {r['side']}: {r['verdict']} (exit {r['exit']}, {r['seconds']} s)", file=sys.stderr)
    rows.sort(key=lambda r: (r["id"], r["side"]))
    json.dump(rows, open(os.path.join(args.work, "robustness.json"), "w"), indent=1)
    text = (table(rows) + "\n\nSelected model against the true model:\n\n" + confusion(rows) +
            f"\n\nAgainst the simplest model the true surface is (its exact points within {SAME_SHAPE_MM} mm RMS):\n\n" +
            confusion(rows, "shape_model") + "\n\n" + resolvable(rows))
    open(os.path.join(args.work, "robustness.md"), "w").write(text + "\n")
    print(text)
    print(f"\n{len(rows)} heads from {len(cts)} CTs in {time.time() - t0:.0f} s wall with -j {args.j}", file=sys.stderr)


if __name__ == "__main__":
    main()
