#!/usr/bin/env python3
"""Clinical failure modes: `articula run` over phantom heads x what clinical
CT adds (arthritis, a clipped field of view, metal, kernels, a contrast
vessel, the table, thick slices, low dose), each case scored against its
truth. See bench/clinical.sh for the usage."""
import argparse
import collections
import concurrent.futures as futures
import json
import os
import subprocess
import sys
import time

# The heads: models, radii 18-28 mm, both sides, 0.6-1 mm within the
# slices, 1-3 mm slices; one of them in a both-hips pelvis CT.
HEADS = [
    dict(id="h0", seed=301, model="sphere", radius=18, side="right", spacing=(0.6, 0.6, 1.0), gap=3.0),
    dict(id="h1", seed=302, model="ellipsoid", radius=22, side="left", spacing=(0.8, 0.8, 1.5), gap=2.5),
    dict(id="h2", seed=303, model="superellipsoid", radius=25, side="right", spacing=(1.0, 1.0, 3.0), gap=3.0),
    dict(id="h3", seed=304, model="ovoid", radius=28, side="left", spacing=(0.7, 0.7, 2.0), gap=4.0),
    dict(id="h4", seed=305, model="superovoid", radius=20, side="right", spacing=(0.9, 0.9, 2.5), gap=2.0),
    dict(id="h5", seed=306, model="ellipsoid", radius=24, side="left", spacing=(1.0, 1.0, 2.0), gap=3.0, both=True),
]
FACES = ["+x", "-x", "+y", "-y", "+z", "-z"]
FACE_NAMES = {"+x": "L", "-x": "R", "+y": "P", "-y": "A", "+z": "S", "-z": "I"}


def modes(head):
    """Each failure mode at its strengths: (mode, strength, phantom arguments)."""
    thick = min(2 * head["spacing"][2], 5.0)
    out = [("none", "", [])]
    out += [("flattened dome", f"{f:g} r", ["--flattened-dome", str(f)]) for f in (0.1, 0.25)]
    out += [("osteophytes", f"{h:g} mm", ["--osteophytes", str(h)]) for h in (1.5, 3.0)]
    out += [("cysts", "", ["--cysts"])]
    out += [("narrow gap", f"{g:g} mm", ["--narrow-gap", str(g)]) for g in (0.8, 0.5)]
    out += [("FOV cut", f"{FACE_NAMES[face]} {int(100 * f)} %", ["--fov-cut", str(f), "--fov-face", face])
            for face in FACES for f in (0.0, 0.1, 0.25, 0.5)]
    out += [("metal", m, ["--metal", m]) for m in ("screw", "stem")]
    out += [("kernel", k, ["--kernel", k]) for k in ("soft", "sharp")]
    out += [("contrast vessel", "", ["--contrast-vessel"]), ("table", "", ["--table"])]
    out += [("slice thickness", f"{thick:g} mm", ["--slice-thickness", str(thick)])]
    out += [("low dose", f"noise {n} HU", ["--noise", str(n)]) for n in (60, 100)]
    # A thin (osteoporotic) cortex is where noise pulls the cortex model's surface outwards.
    out += [("low dose (thin cortex)", f"noise {n} HU", ["--osteoporotic", "--noise", str(n)]) for n in (60, 100)]
    return out


def cases(quick):
    out = []
    for h in HEADS:
        for n, (mode, strength, args) in enumerate(modes(h)):
            out.append(dict(head=h, mode=mode, strength=strength, args=args, id=f"{h['id']}-{n:02d}"))
    if quick:
        keep = {"none", "flattened dome", "metal", "low dose"}
        out = [c for c in out if c["head"]["id"] in ("h1", "h2") and (c["mode"] in keep or c["strength"] in ("S 25 %", "R 10 %"))]
    return out


# Checks whose warnings concern the joint or the run, not the head's surface:
# a case they alone flag is not flagged as a wrong head.
NOT_OF_THE_HEAD = {"side_verified"}


def run_case(case, bin_dir, work):
    h = case["head"]
    d = os.path.join(work, case["id"])
    cmd = [f"{bin_dir}/articula", "phantom", "-o", f"{d}/ct", "--seed", str(h["seed"]), "--exact", "--force", "-q",
           "--no-dicom", "--model", h["model"], "--radius", str(h["radius"]), "--side", h["side"],
           "--spacing", ",".join(map(str, h["spacing"])), "--gap", str(h["gap"]), *case["args"]]
    if h.get("both"):
        cmd.append("--both-hips")
    t0 = time.time()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    phantom_s = time.time() - t0
    out = f"{d}/run"
    t0 = time.time()
    r = subprocess.run([f"{bin_dir}/articula", "run", "-i", f"{d}/ct/phantom.nii.gz", "-o", out, "--joint", "hip",
                        "--side", h["side"], "--force", "-q", "--threads", "1"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    row = dict(id=case["id"], head=h["id"], model=h["model"], radius=h["radius"], side=h["side"],
               spacing="x".join(f"{s:g}" for s in h["spacing"]), mode=case["mode"], strength=case["strength"],
               exit=r.returncode, seconds=round(time.time() - t0, 1), phantom_s=round(phantom_s, 1),
               message=(r.stderr.strip().splitlines() or [""])[-1][:200], flags=[])
    if r.returncode != 0:
        row["verdict"] = "refused"
        return row
    s = subprocess.run([f"{bin_dir}/bench-score-head", f"{d}/ct/truth.json", h["side"], f"{out}/points.ply",
                        f"{out}/results.json"], check=True, capture_output=True, text=True)
    row.update(json.loads(s.stdout))
    results = json.load(open(f"{out}/results.json"))
    checks = results.get("qc", {}).get("checks", [])
    row["flags"] = [f"{c['name']} ({c['status']} {c['value']:.3g})" for c in checks if c["status"] != "pass"]
    row["checks"] = {c["name"]: [c["status"], c["value"]] for c in checks}
    limit = 0.5 * min(h["spacing"][0], h["spacing"][1])
    right = row["rms_mm"] <= limit and row["share_within_1p5_mm"] >= 0.95
    flagged = any(c["status"] != "pass" and c["name"] not in NOT_OF_THE_HEAD for c in checks)
    row["verdict"] = "right" if right else "flagged" if flagged else "SILENTLY WRONG"
    return row


def fmt(v, spec=".2f"):
    return "" if v is None else format(v, spec)


def signed_range(rows):
    """The points' mean signed distances to the true surface (outside
    positive), least to largest."""
    values = [r["mean_signed_mm"] for r in rows if r.get("mean_signed_mm") is not None]
    return f"{min(values):+.3f} to {max(values):+.3f}" if values else ""


def summary(rows):
    """One row per mode and strength: counts of each verdict, and the checks
    that warned or failed (with how many cases)."""
    groups = collections.OrderedDict()
    for r in rows:
        key = (r["mode"], r["strength"] if r["mode"] != "FOV cut" else r["strength"].split(" ", 1)[1])
        groups.setdefault(key, []).append(r)
    lines = ["| mode | strength | cases | right | right, flagged | wrong, flagged | refused | silently wrong | "
             "points' mean signed (mm) | checks that warned or failed (cases) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for (mode, strength), g in groups.items():
        count = collections.Counter(f.split(" (")[0] for r in g for f in r["flags"])
        named = ", ".join(f"{k} ({v})" for k, v in sorted(count.items(), key=lambda kv: -kv[1]))
        right_flagged = sum(r["verdict"] == "right" and bool(r["flags"]) for r in g)
        right_clean = sum(r["verdict"] == "right" for r in g) - right_flagged
        lines.append(f"| {mode} | {strength} | {len(g)} | {right_clean} | {right_flagged} | "
                     f"{sum(r['verdict'] == 'flagged' for r in g)} | {sum(r['verdict'] == 'refused' for r in g)} | "
                     f"{sum(r['verdict'] == 'SILENTLY WRONG' for r in g)} | {signed_range(g)} | {named} |")
    return "\n".join(lines)


def fov_table(rows, check):
    """The field-of-view cuts: per face and depth, how many heads `check`
    flagged (warned or failed) and the range of its values."""
    fov = [r for r in rows if r["mode"] == "FOV cut"]
    if not fov:
        return ""
    depths = sorted({r["strength"].split(" ", 1)[1] for r in fov}, key=lambda s: int(s.split()[0]))
    lines = ["| face | " + " | ".join(depths) + " |", "|---|" + "---|" * len(depths)]
    # The faces, then the left-right faces by side: lateral is the neck's side.
    lateral = lambda r: FACE_NAMES["-x" if r["side"] == "right" else "+x"]
    groups = [(f"{face} ({FACE_NAMES[face]})", lambda r, face=face: r["strength"].startswith(FACE_NAMES[face] + " "))
              for face in FACES]
    groups += [("lateral (the neck's side)", lambda r: r["strength"].startswith(lateral(r) + " ")),
               ("medial", lambda r: r["strength"][0] in "LR" and not r["strength"].startswith(lateral(r) + " "))]
    for title, on_face in groups:
        cells = []
        for depth in depths:
            g = [r for r in fov if on_face(r) and r["strength"].endswith(" " + depth)]
            if not g:
                cells.append("")
                continue
            values = [r.get("checks", {}).get(check) for r in g]
            flagged = sum(v is not None and v[0] != "pass" for v in values)
            shown = [v[1] for v in values if v is not None]
            refused = sum(r["exit"] != 0 for r in g)
            cells.append(f"{flagged}/{len(g)}" + (f" ({min(shown):.3f}-{max(shown):.3f})" if shown else "") +
                         (f", {refused} refused" if refused else ""))
        lines.append(f"| {title} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def cases_table(rows, only_notable=False):
    lines = ["| case | head | spacing (mm) | mode | strength | verdict | exit | RMS (mm) | within 1.5 mm | "
             "mean signed (mm) | centre error (mm) | to the model: RMS (mm) | checks that warned or failed; message |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if only_notable and r["verdict"] == "right":
            continue
        within = fmt(100 * r["share_within_1p5_mm"], ".0f") + " %" if "share_within_1p5_mm" in r else ""
        note = "; ".join(r["flags"]) if r["exit"] == 0 else r["message"]
        lines.append(f"| {r['id']} | {r['head']} ({r['model']}, {r['radius']} mm, {r['side']}) | {r['spacing']} | "
                     f"{r['mode']} | {r['strength']} | {r['verdict']} | {r['exit']} | {fmt(r.get('rms_mm'), '.3f')} | "
                     f"{within} | {fmt(r.get('mean_signed_mm'), '+.3f')} | {fmt(r.get('centre_error_mm'))} | {fmt(r.get('model_rms_mm'), '.3f')} | {note} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("--work", required=True)
    ap.add_argument("-j", type=int, default=1)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--ids", default="", help="comma-separated case ids (e.g. h0-03) or head ids (h2) to run")
    ap.add_argument("--modes", default="", help="comma-separated modes to run, e.g. 'FOV cut,metal'")
    ap.add_argument("--tables-only", action="store_true", help="write the tables again from WORK/clinical.json")
    args = ap.parse_args()
    bin_dir = os.path.abspath(args.bin)
    os.makedirs(args.work, exist_ok=True)
    if args.tables_only:
        write_tables(json.load(open(os.path.join(args.work, "clinical.json"))), args.work)
        return
    todo = cases(args.quick)
    if args.ids:
        ids = args.ids.split(",")
        todo = [c for c in todo if c["id"] in ids or c["head"]["id"] in ids]
    if args.modes:
        todo = [c for c in todo if c["mode"] in args.modes.split(",")]
    t0 = time.time()
    rows = []
    with futures.ThreadPoolExecutor(max_workers=args.j) as pool:
        for done in futures.as_completed([pool.submit(run_case, c, bin_dir, args.work) for c in todo]):
            r = done.result()
            rows.append(r)
            print(f"{r['id']} {r['mode']} {r['strength']}: {r['verdict']} (exit {r['exit']}, {r['seconds']} s) "
                  f"{'; '.join(r['flags'])}", file=sys.stderr)
    rows.sort(key=lambda r: r["id"])
    json.dump(rows, open(os.path.join(args.work, "clinical.json"), "w"), indent=1)
    write_tables(rows, args.work)
    print(f"\n{len(rows)} cases in {time.time() - t0:.0f} s wall with -j {args.j}", file=sys.stderr)


def write_tables(rows, work):
    """Prints the tables and writes them, with every case, to WORK/clinical.md."""
    text = summary(rows)
    for check in ("head_beyond_fov_relative", "head_outside_volume_share"):
        text += f"\n\nField-of-view cuts, heads flagged by {check} (its values):\n\n" + fov_table(rows, check)
    text += "\n\nCases not right:\n\n" + cases_table(rows, only_notable=True)
    open(os.path.join(work, "clinical.md"), "w").write(text + "\n\nEvery case:\n\n" + cases_table(rows) + "\n")
    print(text)


if __name__ == "__main__":
    main()
