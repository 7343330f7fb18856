#!/usr/bin/env bash
# Third-party fluid-coupler check, run by ctest (third_party_fluid_stokes):
#   third_party_fluid_check.sh <domel build dir> <examples/third_party_fluid>
# Builds the uniform_stokes example exactly as a third party would and runs it:
# 1. installs the built domel project into a temporary prefix;
# 2. configures and builds the example against that prefix only
#    (find_package(domel_sdk 2.2) + domel_add_plugin);
# 3. runs scenario.json with the installed domel: every sphere of both levels
#    (alpha = 1 and alpha = 2 with coarse-grain drag scaling) ends at the
#    Stokes terminal velocity of the original sphere,
#    (rho_p - rho_f) g d^2 / (18 mu) = 6.758e-4 m/s, and moves with the
#    liquid along x. The steady state of the refreshed drag is exact and the
#    run lasts 72 relaxation times m/beta, so the tolerance is 1e-9 relative
#    (round-off); summary.json names the model and its library; fluid.pvd is
#    written;
# 4. the same without coarse-grain scaling: the parcels (d = 2 mm) fall at
#    alpha^2 = 4 times that (18 relaxation times of their own: e^-18 = 2e-8,
#    tolerance 1e-6 relative); the real spheres are unchanged;
# 5. `domel validate` on a misspelt parameter: exit code 2 and a did-you-mean;
# 6. removes the temporary folder, whatever happened.
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 <domel build dir> <third-party fluid example dir>" >&2
  exit 64
fi
build=$(cd "$1" && pwd)
project=$(cd "$2" && pwd)
module_name=libdomel_fluid_uniform_stokes.so

tmp=$(mktemp -d "${TMPDIR:-/tmp}/domel_third_party_fluid.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

fail() {
  echo "third_party_fluid_check: FAIL: $*" >&2
  exit 1
}

source "$(dirname "${BASH_SOURCE[0]}")/example_build.sh"
install_and_build_example "$build" "$project" "$tmp" "$module_name"

cp "$project/scenario.json" "$tmp/build/scenario.json"
python3 - "$tmp/build/scenario.json" "$tmp/build/scenario_unscaled.json" <<'PY' || fail "could not write scenario_unscaled.json"
import json, sys
doc = json.load(open(sys.argv[1]))
doc["fluid"]["coarse_grain_scaling"] = False
json.dump(doc, open(sys.argv[2], "w"), indent=2)
PY
for variant in scenario scenario_unscaled; do
  echo "== 3/4. run $variant.json"
  "$domel" run "$tmp/build/$variant.json" --out "$tmp/out_$variant" --quiet >"$tmp/run.log" 2>&1 || {
    rc=$?
    cat "$tmp/run.log" >&2
    fail "domel run $variant.json exited with $rc"
  }
  python3 - "$tmp/out_$variant" "$variant" <<'PY' || fail "$variant: the terminal velocities are wrong"
import csv, json, os, sys
out, variant = sys.argv[1], sys.argv[2]
s = json.load(open(os.path.join(out, "summary.json")))
errors = []
fl = s.get("fluid", {})
if fl.get("model", {}).get("model") != "uniform_stokes" or fl.get("model", {}).get("library") != "third_party_fluid":
    errors.append(f"summary.json fluid.model is {fl.get('model')}, expected uniform_stokes from third_party_fluid")
if s["outputs"].get("fluid") != "fluid.pvd" or not os.path.exists(os.path.join(out, "fluid.pvd")):
    errors.append("no fluid.pvd")
mu, rho_f, rho_p, g, d0, ux = 1.0, 1260.0, 2500.0, 9.81, 0.001, 2e-4
vt = (rho_p - rho_f) * g * d0 ** 2 / (18 * mu)  # Stokes (1851)
for sd in s["subdomains"]:
    name, alpha = sd["name"], sd["coarse_grain"]
    expected = vt if variant == "scenario" or alpha == 1 else alpha ** 2 * vt
    tol = 1e-9 if variant == "scenario" or alpha == 1 else 1e-6
    rows = [r for r in csv.reader(l for l in open(os.path.join(out, s["outputs"]["state"][name])) if not l.startswith("#"))]
    head, rows = rows[0], rows[1:]
    vz = [float(r[head.index("vz")]) for r in rows]
    vx = [float(r[head.index("vx")]) for r in rows]
    worst = max(abs(-v - expected) / expected for v in vz)
    print(f"{variant}: subdomain '{name}' (alpha {alpha}): {len(rows)} spheres, v_z = {vz[0]:.10g} m/s, "
          f"expected -{expected:.10g} (worst relative error {worst:.2g}); v_x = {vx[0]:.10g} (liquid {ux})")
    if worst > tol:
        errors.append(f"'{name}': terminal velocity off by {worst:.3g} (tolerance {tol})")
    if max(abs(v - ux) for v in vx) > tol * ux:
        errors.append(f"'{name}': does not move with the liquid along x")
for e in errors:
    print("error: " + e, file=sys.stderr)
sys.exit(1 if errors else 0)
PY
done

echo "== 5. domel validate reports a misspelt parameter"
sed 's/"viscosity"/"viscosty"/' "$tmp/build/scenario.json" >"$tmp/build/scenario_typo.json"
rc=0
"$domel" validate "$tmp/build/scenario_typo.json" >"$tmp/validate.log" 2>&1 || rc=$?
cat "$tmp/validate.log"
[[ $rc -eq 2 ]] || fail "domel validate exited with $rc on the typo, expected 2"
grep -Fq "unknown property 'viscosty' (did you mean 'viscosity'?)" "$tmp/validate.log" || fail "no did-you-mean for 'viscosty'"

echo "== 6. clean up $tmp"
echo "third_party_fluid_check: OK"
