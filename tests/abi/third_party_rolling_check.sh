#!/usr/bin/env bash
# Third-party rolling plugin check, run by ctest (third_party_rolling_epsd):
#   third_party_rolling_check.sh <domel build dir> <examples/third_party_rolling>
# Builds the EPSD example exactly as a third party would and runs it:
# 1. installs the built domel project into a temporary prefix;
# 2. configures and builds the example project against that prefix only
#    (find_package(domel_sdk 2.0) + domel_add_plugin) into $tmp/build;
# 3. copies scenario.json next to the built libdomel_rolling_epsd.so (the
#    scenario names it by a path relative to itself), runs it with the
#    installed domel, and checks summary.json: rolling model "epsd" from the
#    library "third_party_rolling", and a settled pile (final kinetic energy
#    below 1 % of the run's peak in probes.csv); the same for a copy with the
#    options that make it LIGGGHTS epsd2 (Iwashita-Oda stiffness, no dashpot),
#    and for a copy in which the material pair names epsd
#    (interactions[].rolling) and the subdomain has no rolling model;
# 3b. with an MPI build and mpirun: the scenario for 6000 steps on 2, 3 and 4
#    ranks (the plugin loaded on every rank, never told of the ranks) within
#    1e-6 of one process's largest kinetic energy (round-off);
# 4. `domel validate` on a copy with a misspelt epsd parameter: exit code 2
#    and a did-you-mean naming the right key; the same for a misspelt
#    stiffness value, and `domel run` on viscous damping without a dashpot:
#    a non-zero exit code and the plugin's message;
# 5. removes the temporary folder, whatever happened.
# The example's source folder is only read: nothing is written into it.
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 <domel build dir> <third-party example dir>" >&2
  exit 64
fi
build=$(cd "$1" && pwd)
project=$(cd "$2" && pwd)
module_name=libdomel_rolling_epsd.so

tmp=$(mktemp -d "${TMPDIR:-/tmp}/domel_third_party.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

fail() {
  echo "third_party_rolling_check: FAIL: $*" >&2
  exit 1
}

source "$(dirname "${BASH_SOURCE[0]}")/example_build.sh"
install_and_build_example "$build" "$project" "$tmp" "$module_name"

echo "== 3. run scenario.json with the plugin loaded by path, as LIGGGHTS epsd and as epsd2"
cp "$project/scenario.json" "$tmp/build/scenario.json"
python3 - "$tmp/build/scenario.json" "$tmp/build/scenario_epsd2.json" <<'EOF' || fail "could not write scenario_epsd2.json"
import json, sys
doc = json.load(open(sys.argv[1]))
for sd in doc["subdomains"]:
    sd["contact"]["rolling"] = {"model": "epsd", "rolling_friction": 0.2, "stiffness": "iwashita_oda", "dashpot": False}
json.dump(doc, open(sys.argv[2], "w"), indent=2)
# the model named by the material pair (interactions[].rolling) instead of the subdomain's slot
doc = json.load(open(sys.argv[1]))
for sd in doc["subdomains"]:
    pair_model = sd["contact"].pop("rolling")
for it in doc["interactions"]:
    it["rolling"] = pair_model
json.dump(doc, open(sys.argv[2].replace("epsd2", "pair"), "w"), indent=2)
EOF
for variant in scenario scenario_epsd2 scenario_pair; do
echo "-- $variant.json"
"$domel" run "$tmp/build/$variant.json" --out "$tmp/out_$variant" --quiet >"$tmp/run.log" 2>&1 || {
  rc=$?
  cat "$tmp/run.log" >&2
  fail "domel run $variant.json exited with $rc"
}
cat "$tmp/run.log"
if grep "refused" "$tmp/run.log" | grep -q "$module_name"; then
  fail "domel refused $module_name"
fi
[[ -f "$tmp/out_$variant/summary.json" ]] || fail "no summary.json in $tmp/out_$variant"
python3 - "$tmp/out_$variant" "$tmp/build/$module_name" <<'EOF' || fail "summary.json check failed"
import csv, json, os, sys
out, module = sys.argv[1], sys.argv[2]
s = json.load(open(os.path.join(out, "summary.json")))
errors = []
# the subdomain's rolling slot, or (scenario_pair) the model the pair (beads, beads) names
rolling = [(name, slots.get("rolling") or slots.get("rolling (beads, beads)")) for name, slots in s["models"].items()]
for name, r in rolling:
    if not r or r.get("model") != "epsd" or r.get("library") != "third_party_rolling":
        errors.append(f"subdomain '{name}': rolling slot is {r}, expected model 'epsd' from 'third_party_rolling'")
    else:
        print(f"summary.json: subdomain '{name}' rolling = {json.dumps(r, sort_keys=True)}")
libs = [l for l in s["plugin_libraries"] if l["name"] == "third_party_rolling"]
if len(libs) != 1 or os.path.realpath(libs[0]["path"]) != os.path.realpath(module):
    errors.append(f"plugin_libraries does not list third_party_rolling at {module}: {s['plugin_libraries']}")
else:
    print(f"summary.json: library {json.dumps(libs[0], sort_keys=True)}")
# The pile settles: the final kinetic energy (translational + rotational) is
# below 1 % of the peak of the run (probes.csv). Typical: 1e-4 of the peak.
rows = list(csv.DictReader(open(os.path.join(out, "probes.csv"))))
for sd in s["subdomains"]:
    name, fin = sd["name"], sd["final"]
    ke = fin["ke_translational_J"] + fin["ke_rotational_J"]
    peak = max(float(r[f"{name}.ke_translational"]) + float(r[f"{name}.ke_rotational"]) for r in rows)
    print(f"subdomain '{name}': {sd['particles']} particles, {sd['steps']} steps; final KE {ke:.3g} J "
          f"(translational {fin['ke_translational_J']:.3g}, rotational {fin['ke_rotational_J']:.3g}), "
          f"peak KE {peak:.3g} J, ratio {ke / peak if peak > 0 else float('nan'):.2g}; "
          f"mean |omega| {fin['mean_angular_speed']:.3g} rad/s; {fin['contacts']} contacts")
    if not (peak > 0 and ke < 0.01 * peak):
        errors.append(f"subdomain '{name}' has not settled: final KE {ke:.3g} J vs peak {peak:.3g} J")
for e in errors:
    print("error: " + e, file=sys.stderr)
sys.exit(1 if errors else 0)
EOF
done

echo "== 3b. the same plugin in a run spread over 2, 3 and 4 MPI ranks (mpirun), against one process"
if command -v mpirun >/dev/null && ldd "$domel" | grep -q libmpi; then
  "$domel" run "$tmp/build/scenario.json" --out "$tmp/out_one" --quiet --max-steps 6000 >"$tmp/run.log" 2>&1 ||
    { cat "$tmp/run.log" >&2; fail "domel run (6000 steps) failed"; }
  for np in 2 3 4; do
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,vader \
      timeout 300 mpirun -np $np --oversubscribe "$domel" run "$tmp/build/scenario.json" --out "$tmp/out_np$np" \
      --quiet --max-steps 6000 >"$tmp/run.log" 2>&1 || { cat "$tmp/run.log" >&2; fail "mpirun -np $np failed"; }
    # the pile falls and collides for 6000 steps (0.06 s): within round-off of one process
    # (the tolerance 1e-6 of the largest kinetic energy is the MPI CLI test's)
    python3 - "$tmp/out_one" "$tmp/out_np$np" "$np" <<'EOF' || fail "the run on $np ranks differs from one process"
import csv, json, os, sys
one, many, np = sys.argv[1], sys.argv[2], sys.argv[3]
s = json.load(open(os.path.join(many, "summary.json")))
assert s["ranks"] == int(np), s["ranks"]
assert s["models"]["pile"]["rolling"]["library"] == "third_party_rolling", s["models"]
rows = [list(csv.DictReader(open(os.path.join(d, "probes.csv")))) for d in (one, many)]
assert len(rows[0]) == len(rows[1]) > 5
peak = max(float(r["pile.ke_translational"]) for r in rows[0])
worst = max(abs(float(a[c]) - float(b[c])) / peak for a, b in zip(*rows)
            for c in ("pile.ke_translational", "pile.ke_rotational"))
print(f"epsd on {np} ranks: kinetic energies within {worst:.3g} of one process's largest")
sys.exit(0 if worst < 1e-6 else 1)
EOF
  done
else
  echo "(no MPI build or no mpirun: skipped)"
fi

echo "== 4. domel validate reports a misspelt epsd parameter"
sed 's/"rolling_friction"/"rolling_fricton"/' "$tmp/build/scenario.json" >"$tmp/build/scenario_typo.json"
grep -q '"rolling_fricton"' "$tmp/build/scenario_typo.json" || fail "could not make the typo copy"
rc=0
"$domel" validate "$tmp/build/scenario_typo.json" >"$tmp/validate.log" 2>&1 || rc=$?
cat "$tmp/validate.log"
[[ $rc -eq 2 ]] || fail "domel validate exited with $rc on the typo, expected 2"
grep -Fq "unknown property 'rolling_fricton' (did you mean 'rolling_friction'?)" "$tmp/validate.log" ||
  fail "no did-you-mean for 'rolling_fricton'"
grep -Fq "missing required property 'rolling_friction'" "$tmp/validate.log" ||
  fail "the missing required 'rolling_friction' is not reported"

echo "== 4b. a misspelt stiffness, and viscous damping without a dashpot"
sed 's/"iwashita_oda"/"iwashita"/' "$tmp/build/scenario_epsd2.json" >"$tmp/build/scenario_enum.json"
rc=0
"$domel" validate "$tmp/build/scenario_enum.json" >"$tmp/validate.log" 2>&1 || rc=$?
cat "$tmp/validate.log"
[[ $rc -eq 2 ]] || fail "domel validate exited with $rc on stiffness 'iwashita', expected 2"
grep -Fq "iwashita_oda" "$tmp/validate.log" || fail "the error for stiffness 'iwashita' does not name 'iwashita_oda'"
sed 's/"dashpot": false/"dashpot": false, "viscous_damping": 0.3/' "$tmp/build/scenario_epsd2.json" \
  >"$tmp/build/scenario_contradiction.json"
grep -q '"viscous_damping": 0.3' "$tmp/build/scenario_contradiction.json" || fail "could not make the contradiction copy"
rc=0
"$domel" run "$tmp/build/scenario_contradiction.json" --out "$tmp/out_contradiction" --quiet >"$tmp/run.log" 2>&1 || rc=$?
cat "$tmp/run.log"
[[ $rc -ne 0 ]] || fail "domel run accepted viscous_damping 0.3 with dashpot false"
grep -Fq "'dashpot' is false" "$tmp/run.log" || fail "the plugin's message about the dashpot is not shown"

echo "== 5. clean up $tmp"
echo "third_party_rolling_check: OK"
