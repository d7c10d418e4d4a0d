#!/usr/bin/env bash
# Cohort scale: a study of N subjects (default 1,000) made from two real runs
# (a right and a left phantom hip) copied with perturbed values (radii,
# centres and errors scaled by a seeded factor per subject, every tenth
# subject's checks made to warn, one in fifty failed). Measures:
#   - the Snakefile's graph for the cohort: `snakemake -n` (target <= 30 s);
#   - gathering the study and its pages: `articula batch --gather-only`
#     (target <= 30 s), and the size of study.html (target <= 5 MB).
#   bash bench/cohort_scale.sh [build/bin] [scratch dir] [N]
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
bin=$(cd "${1:-build/bin}" && pwd)
work=${2:-$(mktemp -d)}
n=${3:-1000}
mkdir -p "$work"
for side in right left; do
  [ -f "$work/runs/$side/results.json" ] && continue
  "$bin/articula" phantom -o "$work/ct/$side" --seed 7 --side "$side" --spacing 1.2,1.2,1.5 --no-dicom --quiet --force
  "$bin/articula" run -i "$work/ct/$side/phantom.nii.gz" --joint hip --side "$side" -o "$work/runs/$side" --quiet --force
done
python3 - "$work" "$n" <<'PY'
import json, os, random, shutil, sys
work, n = sys.argv[1], int(sys.argv[2])
random.seed(11)
study = os.path.join(work, "study")
shutil.rmtree(study, ignore_errors=True)
rows = ["subject,input,joint,side"]
def scaled(value, factor):
    return value * factor if isinstance(value, float) else value
for i in range(n):
    subject, side = f"s{i:04d}", ("right", "left")[i % 2]
    rows.append(f"{subject},ct/{side}/phantom.nii.gz,hip,{side}")
    folder = os.path.join(study, "subjects", subject)
    if i % 50 == 49:
        os.makedirs(folder)
        json.dump({"subject": subject, "status": "failed", "exit_code": 1, "seconds": 3.0, "command": "articula run",
                   "message": "no head found"}, open(os.path.join(folder, "status.json"), "w"))
        continue
    shutil.copytree(os.path.join(work, "runs", side), folder, ignore=shutil.ignore_patterns("*.nii.gz", "*.vtp", "*.ply", ".articula"))
    results = json.load(open(os.path.join(folder, "results.json")))
    size, error = random.uniform(0.85, 1.2), random.uniform(0.7, 1.5)
    for model in results["models"]:
        for key, value in model["parameters"].items():
            if key.endswith("_mm") and key[0] in "abc":
                model["parameters"][key] = scaled(value, size)
            elif key in ("t1_mm", "t2_mm", "t3_mm"):
                model["parameters"][key] = value + random.gauss(0, 5)
        for key in ("rms_mm", "mean_abs_mm", "sse_mm2"):
            if key in model["errors"]:
                model["errors"][key] = scaled(model["errors"][key], error)
    if i % 10 == 9:
        results["qc"]["status"] = "warn"
        results["qc"]["reasons"] = ["head_radius_mm: a doubtful radius (made up for the benchmark)"]
    json.dump(results, open(os.path.join(folder, "results.json"), "w"), indent=1)
    json.dump({"subject": subject, "status": "ok", "exit_code": 0, "seconds": 20.0, "command": "articula run"},
              open(os.path.join(folder, "status.json"), "w"))
open(os.path.join(work, "study.csv"), "w").write("\n".join(rows) + "\n")
PY
now() { date +%s.%N; }
t0=$(now)
snakemake -n -q -s "$src/pipelines/Snakefile" --profile "$src/pipelines/profiles/local" \
  --config manifest="$work/study.csv" study="$work/snake" bin="$bin" > "$work/dry-run.log" 2>&1
t1=$(now)
"$bin/articula" batch "$work/study.csv" -o "$work/study" --gather-only --quiet || [ $? -eq 1 ]
t2=$(now)
python3 - "$t0" "$t1" "$t2" "$work/study/study.html" "$n" <<'PY'
import os, sys
t0, t1, t2 = map(float, sys.argv[1:4])
size = os.path.getsize(sys.argv[4])
print(f"cohort of {sys.argv[5]}: snakemake graph (dry run) {t1 - t0:.1f} s (target 30); "
      f"gather and pages {t2 - t1:.1f} s (target 30); study.html {size / 1e6:.2f} MB (target 5)")
PY
