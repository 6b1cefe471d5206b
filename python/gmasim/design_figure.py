"""design.png of ``gmasim design --plot`` (gmasim.command_figures' renderer for "design")."""
from __future__ import annotations

import pathlib

import numpy as np

from gmasim.plots import plt, read_csv, read_meta

_DESIGN_LABELS = {
    "stroke_um": "stroke at {T} °C (µm)", "hysteresis_um": "hysteresis at {T} °C (µm)",
    "B_pp_T": "B peak-to-peak at {T} °C (T)", "retention_pct": "stroke retention {T} (%)",
    "coil_copper_loss_W": "coil copper loss at {T} °C (W)",
    "temperature_rise_K": "steady rise at {T} °C (K)", "bandwidth_Hz": "−3 dB bandwidth (Hz)",
    "first_resonance_Hz": "first resonance (Hz)", "rods_mass_kg": "rods' mass (kg)",
    "coil_resistance_ohm": "coil resistance (Ω)", "current_peak_A": "peak current (A)"}


def _design_label(q: str) -> str:
    name, _, temps = q.partition("@")
    return _DESIGN_LABELS.get(name, name).format(T=temps.replace(":", " → ") + (" °C" if ":" in temps else ""))


def design(out):
    """design.png: the last generation in the plane of the first two objectives (feasible,
    infeasible, failed), the Pareto front drawn through its points."""
    out = pathlib.Path(out)
    pop = read_csv(out / "design_population.csv")
    meta = read_meta(out, "design")
    objectives = [o.split(" ", 1) for o in meta["objectives"].split(", ")]
    (_, qx), (_, qy) = objectives[0], objectives[1]
    failed = pop["failed"] == "true"
    feasible = ~failed & (pop["violation"] == 0)
    front = pop["on_front"] == "true"
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    dominated = feasible & ~front
    if dominated.any():
        ax.plot(pop[qx][dominated], pop[qy][dominated], "o", ms=5, mfc="none", color="tab:blue",
                label="feasible, dominated")
    infeasible = ~failed & ~feasible
    if infeasible.any():
        ax.plot(pop[qx][infeasible], pop[qy][infeasible], "x", ms=5, color="tab:red",
                label="breaks a constraint")
    order = np.argsort(pop[qx][front])
    ax.plot(pop[qx][front][order], pop[qy][front][order], "o-", ms=6, color="tab:green",
            label=f"Pareto front ({int(front.sum())})")
    ax.set_xlabel(f"{_design_label(qx)} [{objectives[0][0]}]")
    ax.set_ylabel(f"{_design_label(qy)} [{objectives[1][0]}]")
    ax.grid(alpha=0.3)
    n_failed = int(failed.sum())
    ax.legend(fontsize=7, title=f"{n_failed} failed (not drawn)" if n_failed else None, title_fontsize=7)
    ax.set_title(f"gmasim design: generation {meta.get('generations', '?')}, "
                 f"population {meta.get('population', '?')}\nconstraints: {meta.get('constraints', 'none')}",
                 fontsize=9)
    fig.tight_layout()
    return fig
