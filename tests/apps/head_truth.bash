# Shared by the head-isolation scripts (sourced, not a test itself): a
# run's head against a phantom's truth.

# check RUN TRUTH SIDE MAX_CENTRE_ERROR MAX_RMS: the run's head against the truth of SIDE.
check() {
  python3 - "$1" "$2" "$3" "$4" "$5" <<'PY'
import json, math, sys
run, truth_path, side, max_centre, max_rms = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), float(sys.argv[5])
truth = json.load(open(truth_path))
head = next((h for h in truth.get("hips", []) if h.get("side") == side), truth)
r = json.load(open(f"{run}/results.json"))
sphere = next(m for m in r["models"] if m["model"] == "sphere")
centre = [sphere["parameters"][k] for k in ("t1_mm", "t2_mm", "t3_mm")]  # the sphere's: an ovoid's centre is not the head's
err = math.dist(centre, head["head_center_mm"])
radius = sphere["parameters"]["a_mm"]
print(f"{run}: sphere centre error {err:.2f} mm, sphere radius {radius:.2f} mm (true radii {[round(x, 1) for x in head['radii_mm']]}), "
      f"qc {r['qc']['status']}, best-model RMS {min(m['errors']['rms_mm'] for m in r['models']):.3f} mm")
assert err < max_centre, f"head centre {err:.2f} mm from the truth"
assert min(head["radii_mm"]) - 1.0 < radius < max(head["radii_mm"]) + 1.0, radius
assert r["qc"]["status"] in ("pass", "warn"), r["qc"]
assert sphere["errors"]["rms_mm"] < max_rms, sphere["errors"]["rms_mm"]
PY
}
