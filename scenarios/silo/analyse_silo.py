#!/usr/bin/env python3
"""Silo discharge analysis: the measured steady discharge rate of one or more
runs of scenarios/silo/*.json against the Beverloo law (shared physics.md
§6.1: W = C rho_b sqrt(g) (D_o - k d)^(5/2), C = 0.58, k = 1.5), with the bulk
density rho_b = phi rho_p measured by the run's own cell grid in the settled
bed just before the outlet opens (mean volume fraction of the layers between
20 % and 80 % of the bed height, weighted by accessible volume). Prints a
table, writes <out>/silo_results.json and, with matplotlib, PNG plots of the
discharged mass over time and of the pressure and volume fraction over height.

Usage: analyse_silo.py [--out DIR] SCENARIO.json:RUN_DIR [SCENARIO.json:RUN_DIR ...]
The first pair is the reference (the fine case) for the deviation column."""
import argparse, csv, json, math, os, sys

C_BEV, K_BEV, G = 0.58, 1.5, 9.81


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    head = rows[0]
    return head, [[float(v) if v not in ("", "nan") else float("nan") for v in r] for r in rows[1:]]


def profile_at(path, t_want):
    """Layer rows of the grid profile written last at or before t_want."""
    head, rows = read_csv(path)
    col = {h: i for i, h in enumerate(head)}
    times = sorted({r[col["time"]] for r in rows})
    before = [t for t in times if t <= t_want + 1e-9]
    t = before[-1] if before else times[0]
    layers = [r for r in rows if r[col["time"]] == t]
    return t, [{h: r[col[h]] for h in head} for r in layers]


def analyse(scenario_path, run_dir):
    sc = json.load(open(scenario_path))
    silo = next(w for w in sc["walls"] if w["type"] == "cylinder")
    Do = 2 * silo["outlet_radius"]
    t_open = silo["outlet_open_at"]
    sd = sc["subdomains"][0]
    alpha = sd.get("coarse_grain", 1)
    d = sd["pour"][0]["insert"]["diameter"] * alpha
    rho_p = sc["materials"][sd["material"]]["density"]
    summary = json.load(open(os.path.join(run_dir, "summary.json")))
    steady = summary["deletion_regions"]["outlet"]["steady"]
    rate = steady["rate_kg_s"]
    window = steady["window_s"]
    plane_rate = summary["mass_flow"]["orifice"]["steady"]["rate_kg_s"]
    grid = sc["output"]["grids"][0]["name"]
    t_prof, layers = profile_at(os.path.join(run_dir, grid + "_profile.csv"), t_open)
    filled = [l for l in layers if l["volume_fraction"] > 0.3]
    top = max(l["centre"] for l in filled) if filled else 0.0
    band = [l for l in filled if 0.2 * top <= l["centre"] <= 0.8 * top]
    phi = sum(l["volume_fraction"] * l["accessible_volume"] for l in band) / sum(l["accessible_volume"] for l in band)
    rho_b = phi * rho_p
    beverloo = C_BEV * rho_b * math.sqrt(G) * (Do - K_BEV * d) ** 2.5
    head, rows = read_csv(os.path.join(run_dir, "probes.csv"))
    col = {h: i for i, h in enumerate(head)}
    series = [(r[col["time"]], r[col["outlet.removed_kg"]]) for r in rows]
    bal = summary["mass_balance"][sd["name"]]
    return {
        "scenario": os.path.basename(scenario_path), "run": run_dir, "alpha": alpha, "particles": bal["inserted"],
        "d_m": d, "outlet_m": Do, "outlet_over_d": Do / d, "phi_bed": phi, "rho_bulk": rho_b, "profile_time_s": t_prof,
        "rate_kg_s": rate, "plane_rate_kg_s": plane_rate, "window_s": window, "beverloo_kg_s": beverloo,
        "beverloo_deviation": rate / beverloo - 1.0, "wall_time_s": summary["wall_time_s"],
        "threads": summary["threads"], "steps": summary["steps"], "time_step_s": summary["subdomains"][0]["time_step_s"],
        "particle_steps_per_s": summary["particle_steps_per_s"], "mass_balance_exact": bal["exact"],
        "mass_balance": bal, "discharge_series": series, "layers": layers, "t_open": t_open,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("Usage")[0])
    ap.add_argument("--out", default=".")
    ap.add_argument("runs", nargs="+", help="SCENARIO.json:RUN_DIR")
    args = ap.parse_args()
    results = [analyse(*r.split(":", 1)) for r in args.runs]
    ref = results[0]
    print(f"{'scenario':18} {'alpha':>5} {'N':>7} {'Do/d':>5} {'phi':>6} {'W [kg/s]':>9} {'plane':>8} "
          f"{'Beverloo':>9} {'vs Bev':>7} {'vs ref':>7} {'wall [s]':>9} {'balance':>8}")
    for r in results:
        r["deviation_from_reference"] = r["rate_kg_s"] / ref["rate_kg_s"] - 1.0
        r["speedup_vs_reference"] = ref["wall_time_s"] / r["wall_time_s"]
        print(f"{r['scenario']:18} {r['alpha']:>5} {r['particles']:>7} {r['outlet_over_d']:>5.1f} {r['phi_bed']:>6.3f} "
              f"{r['rate_kg_s']:>9.4f} {r['plane_rate_kg_s']:>8.4f} {r['beverloo_kg_s']:>9.4f} "
              f"{100 * r['beverloo_deviation']:>+6.1f}% {100 * r['deviation_from_reference']:>+6.1f}% "
              f"{r['wall_time_s']:>9.1f} {'exact' if r['mass_balance_exact'] else 'OFF':>8}")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "silo_results.json"), "w") as f:
        json.dump([{k: v for k, v in r.items() if k not in ("discharge_series", "layers")} for r in results], f,
                  indent=2)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not found: no plots (run with /usr/bin/python3)", file=sys.stderr)
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    for r in results:
        t = [p[0] for p in r["discharge_series"]]
        m = [p[1] for p in r["discharge_series"]]
        ax.plot(t, m, label=f"{r['scenario']} (alpha {r['alpha']}): {r['rate_kg_s']:.3f} kg/s")
        t0 = r["window_s"][0]
        ax.plot([t0, r["window_s"][1]], [0, r["beverloo_kg_s"] * (r["window_s"][1] - t0)], "--",
                label=f"Beverloo slope {r['beverloo_kg_s']:.3f} kg/s (alpha {r['alpha']})")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("discharged mass [kg]")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "silo_discharge.png"), dpi=120)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(8, 4), sharey=True)
    for r in results:
        z = [l["centre"] for l in r["layers"]]
        a1.plot([l["pressure"] for l in r["layers"]], z, "o-", ms=3, label=f"{r['scenario']} (alpha {r['alpha']})")
        a2.plot([l["volume_fraction"] for l in r["layers"]], z, "o-", ms=3, label=r["scenario"])
    a1.set_xlabel("pressure p = tr(sigma)/3 [Pa]")
    a1.set_ylabel("height z [m]")
    a2.set_xlabel("volume fraction")
    a1.set_title(f"settled bed at t = {ref['profile_time_s']:.2f} s", fontsize=9)
    a1.legend(fontsize=7)
    for a in (a1, a2):
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "silo_pressure_profile.png"), dpi=120)
    print("wrote", os.path.join(args.out, "silo_discharge.png"), "and silo_pressure_profile.png")


if __name__ == "__main__":
    main()
