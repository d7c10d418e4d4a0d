#!/usr/bin/env python3
"""Coverage of the 95 % intervals of centre and semi-axes, and the selected
model against the true one, over the runs of the phantom benches
(bench/robustness.sh, bench/independent_phantoms.sh, bench/third_phantoms.sh)
whose truth is known. Reads their WORK folders as they left them; recomputes
the intervals of every fitted model that contains the true model with each
method of lib/fit uncertainty.hpp (bench-coverage).

  python3 bench/coverage.py --bin build/bin [--robustness WORK] [--independent WORK] [--third WORK] [--out FILE.json]
"""
import argparse
import glob
import json
import math
import os
import subprocess
import sys
import tempfile


def robustness_cases(work):
    for truth_path in sorted(glob.glob(f"{work}/*/ct/truth.json")):
        d = os.path.dirname(os.path.dirname(truth_path))
        truth = json.load(open(truth_path))
        for h in truth.get("hips", []):
            run = f"{d}/run-{h['side']}"
            if not os.path.exists(f"{run}/results.json") or not os.path.exists(f"{run}/fits.json"):
                continue
            yield dict(id=f"{os.path.basename(d)}-{h['side']}", set="robustness", run=run,
                       truth=dict(model=h["model"], center_mm=h["head_center_mm"], radii_mm=h["radii_mm"],
                                  angles_rad=h["angles_rad"], exponents=h["exponents"], cx=h["cx"], cy=h["cy"]))


def independent_cases(work):
    for run in sorted(glob.glob(f"{work}/run-*")):
        name = os.path.basename(run)[4:]
        if not os.path.isdir(run) or not os.path.exists(f"{run}/results.json") or not os.path.exists(f"{work}/{name}.json"):
            continue
        t = json.load(open(f"{work}/{name}.json"))
        model = "sphere" if max(t["radii_mm"]) - min(t["radii_mm"]) < 1e-9 else "ellipsoid"
        yield dict(id=name, set="independent", run=run,
                   truth=dict(model=model, center_mm=t["head_center_mm"], radii_mm=t["radii_mm"],
                              axes_columns=[[1, 0, 0], [0, 1, 0], [0, 0, 1]]))


def third_cases(work):
    for run in sorted(glob.glob(f"{work}/run-*")):
        if not os.path.isdir(run) or not os.path.exists(f"{run}/results.json"):
            continue
        name, side = os.path.basename(run)[4:].rsplit("-", 1)
        t = json.load(open(f"{work}/{name}.json"))
        h = next(h for h in t["heads"] if h["side"] == side)
        A = h["axes_lps_columns"]  # rows of this list are the matrix's rows
        columns = [[A[r][c] for r in range(3)] for c in range(3)]
        model = "sphere" if max(h["radii_mm"]) - min(h["radii_mm"]) < 1e-9 else "ellipsoid"
        D = t.get("direction_lps", [[1, 0, 0], [0, 1, 0], [0, 0, 1]])
        yield dict(id=f"{name}-{side}", set="third", run=run, slice_axis=[D[r][2] for r in range(3)],
                   truth=dict(model=model, center_mm=h["head_center_mm"], radii_mm=h["radii_mm"], axes_columns=columns))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("--robustness")
    ap.add_argument("--independent")
    ap.add_argument("--third")
    ap.add_argument("--out")
    ap.add_argument("--methods", default="", help="comma-separated (default: all four)")
    a = ap.parse_args()
    cases = []
    for work, make in ((a.robustness, robustness_cases), (a.independent, independent_cases), (a.third, third_cases)):
        if work:
            cases += list(make(work))
    for c in cases:
        c["points"], c["fits"] = f"{c['run']}/points.ply", f"{c['run']}/fits.json"
        sp = json.load(open(f"{c['run']}/label.nii.gz.json")).get("spacing_mm")
        if sp:
            c["spacing_mm"], c["slice_axis"] = sp, c.get("slice_axis", [0, 0, 1])
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(cases, f)
    methods = [m for m in a.methods.split(",") if m]
    out = subprocess.run([f"{a.bin}/bench-coverage", f.name, *methods], check=True, capture_output=True, text=True)
    os.unlink(f.name)
    if out.stderr:
        print(out.stderr, file=sys.stderr)
    rows = [json.loads(line) for line in out.stdout.splitlines()]
    sets = {c["id"]: c["set"] for c in cases}
    selected = {}
    for c in cases:
        r = json.load(open(f"{c['run']}/results.json"))
        selected[c["id"]] = (c["truth"]["model"], r.get("selected_model"))
    for r in rows:
        r["set"] = sets[r["id"]]
    if a.out:
        json.dump(dict(rows=rows, selected=selected), open(a.out, "w"), indent=1)
    print(report(rows, selected, sets))


def share(zs):
    zs = [z for z in zs if z is not None and not (isinstance(z, float) and math.isnan(z))]
    return (f"{100.0 * sum(abs(z) <= 1.96 for z in zs) / len(zs):.0f} % of {len(zs)}", zs) if zs else ("-", zs)


def median(v):
    v = sorted(v)
    return v[len(v) // 2] if v else float("nan")


def report(rows, selected, sets):
    lines = []
    methods = ["independent", "spatial-model", "spatial-hac", "patch-bootstrap"]
    for set_name in ["robustness", "independent", "third", "all"]:
        g = [r for r in rows if set_name in ("all", r["set"])]
        if not g:
            continue
        lines += [f"\n{set_name}: 95 % intervals holding the truth (the true model's own fit and every model containing it)",
                  "| method | fits | centre | semi-axes | semi-axes less the shared offset | median abs(z) centre | max abs(z) centre |",
                  "|---|---|---|---|---|---|---|"]
        for m in methods:
            h = [r for r in g if r["method"] == m]
            if not h:
                continue
            cz = [z for r in h for z in r["centre_z"]]
            rz = [z for r in h for z in r["radius_z"]]
            oz = [z for r in h for z in r["radius_less_offset_z"]]
            c_text, c_vals = share(cz)
            lines.append(f"| {m} | {len(h)} | {c_text} | {share(rz)[0]} | {share(oz)[0]} | "
                         f"{median([abs(z) for z in c_vals]):.2f} | {max([abs(z) for z in c_vals] or [float('nan')]):.1f} |")
        own = [r for r in g if r["model"] == r["true_model"] or (r["true_model"] == "sphere" and r["model"] == "sphere")]
        lines += ["", "| method (the true model's own fit) | fits | centre | semi-axes less the shared offset |", "|---|---|---|---|"]
        for m in methods:
            h = [r for r in own if r["method"] == m]
            if not h:
                continue
            lines.append(f"| {m} | {len(h)} | {share([z for r in h for z in r['centre_z']])[0]} | "
                         f"{share([z for r in h for z in r['radius_less_offset_z']])[0]} |")
        lines += ["", "| fitted model | method | fits | centre | semi-axes less the shared offset |", "|---|---|---|---|---|"]
        for model in ["sphere", "ellipsoid", "superellipsoid", "ovoid", "superovoid"]:
            for m in methods:
                h = [r for r in g if r["method"] == m and r["model"] == model]
                if h:
                    lines.append(f"| {model} | {m} | {len(h)} | {share([z for r in h for z in r['centre_z']])[0]} | "
                                 f"{share([z for r in h for z in r['radius_less_offset_z']])[0]} |")
        sm = [r for r in g if r["method"] == "spatial-model"]
        if sm:
            lines.append(f"\nmedian n_eff {median([r['n_eff'] for r in sm]):.1f} of median n {median([r['n'] for r in sm])}; "
                         f"median lengths {median([r['lengths_mm'][0] for r in sm]):.2f} / {median([r['lengths_mm'][1] for r in sm]):.1f} mm; "
                         f"median shared offset {median([r['offset_mm'] for r in sm]):+.3f} mm")
    models = ["sphere", "ellipsoid", "superellipsoid", "ovoid", "superovoid"]
    rob = {k: v for k, v in selected.items() if sets[k] == "robustness"}
    if rob:
        lines += ["\nselected model against the true one (robustness matrix)",
                  "| true \\ selected | " + " | ".join(models) + " | heads | correct |", "|---|" + "---|" * 7]
        right = 0
        for t in models:
            g = [s for (tm, s) in rob.values() if tm == t]
            counts = [sum(s == m for s in g) for m in models]
            right += counts[models.index(t)]
            lines.append(f"| {t} | " + " | ".join(map(str, counts)) + f" | {len(g)} | "
                         f"{100.0 * counts[models.index(t)] / len(g) if g else 0:.0f} % |")
        lines.append(f"\n{right} of {len(rob)} right")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
