"""The sensitivity heatmap of ``gmasim sensitivity`` (re-exported as gmasim.plots.sensitivity_heatmap)."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from .plots import plt


def sensitivity_heatmap(quantities: Sequence[str], parameters: Sequence[str], per_tolerance,
                        flags=None, correlation=None, relative_rows: Sequence[bool] | None = None,
                        title="Sensitivity: d q / d ln p per tolerance"):
    """Heatmap of ``per_tolerance[i, j]`` (quantity i, parameter j: the change of q, in units
    of its tolerance, per unit relative change of the parameter) on a symmetric-log colour
    scale; flagged entries (``flags[i, j] != "ok"``) crossed out. ``relative_rows`` marks rows
    without a tolerance (ranking claims) normalised by 10 % of their value instead (label
    ending in "*"). With ``correlation`` (P x P) a second panel shows the parameters'
    correlations from identifiability."""
    from matplotlib.colors import SymLogNorm

    S = np.asarray(per_tolerance, dtype=float)
    nq, npar = S.shape
    panels = 2 if correlation is not None else 1
    fig = plt.figure(figsize=(4.2 + 0.55 * npar * panels + 1.8 * (panels - 1),
                              max(3.8, 2.4 + 0.26 * nq)))
    ax = fig.add_subplot(1, panels, 1)
    finite = S[np.isfinite(S)]
    vmax = max(float(np.max(np.abs(finite))) if finite.size else 1.0, 1.0)
    norm = SymLogNorm(linthresh=0.1, vmin=-vmax, vmax=vmax, base=10)
    im = ax.imshow(np.ma.masked_invalid(S), cmap="RdBu_r", norm=norm, aspect="auto",
                   interpolation="nearest")
    labels = [q + ("*" if relative_rows is not None and relative_rows[i] else "")
              for i, q in enumerate(quantities)]
    ax.set_yticks(range(nq), labels, fontsize=7)
    ax.set_xticks(range(npar), parameters, fontsize=7, rotation=60, ha="right",
                  rotation_mode="anchor")
    ax.set_xlabel("parameter")
    ax.set_ylabel("quantity (claim or metric)")
    fl = np.asarray(flags) if flags is not None else np.full(S.shape, "ok", dtype=object)
    if nq * npar <= 800:  # the value in each cell, except a crossed-out (flagged) one
        for i in range(nq):
            for j in range(npar):
                if np.isfinite(S[i, j]) and abs(S[i, j]) >= 0.05 and fl[i, j] == "ok":
                    ax.text(j, i, f"{S[i, j]:.2g}", ha="center", va="center", fontsize=6,
                            color="white" if abs(S[i, j]) > 0.3 * vmax else "black")
    for i, j in zip(*np.nonzero(fl != "ok")):
        ax.plot([j - 0.45, j + 0.45], [i - 0.45, i + 0.45], color="black", lw=0.8)
        ax.plot([j - 0.45, j + 0.45], [i + 0.45, i - 0.45], color="black", lw=0.8)
    # Colour-bar ticks: zero, +-1 tolerance and the extremes, not every decade (they crowd).
    top = float(10 ** np.floor(np.log10(vmax)))
    ticks = sorted({-top, -1.0, 0.0, 1.0, top})
    cb = fig.colorbar(im, ax=ax, shrink=0.8, ticks=ticks)
    cb.ax.set_yticklabels([f"{t:g}" for t in ticks], fontsize=7)
    cb.set_label("Δq per tolerance per unit ln p (-)", fontsize=7)
    ax.set_title("sensitivity (crossed: flagged)", fontsize=8)
    if correlation is not None:
        C = np.asarray(correlation, dtype=float)
        ax2 = fig.add_subplot(1, panels, 2)
        im2 = ax2.imshow(np.ma.masked_invalid(C), cmap="RdBu_r", vmin=-1, vmax=1,
                         interpolation="nearest")
        ax2.set_xticks(range(npar), parameters, fontsize=7, rotation=60, ha="right",
                       rotation_mode="anchor")
        ax2.set_yticks(range(npar), parameters, fontsize=7)
        ax2.set_xlabel("parameter")
        ax2.set_ylabel("parameter")
        for i in range(npar):
            for j in range(npar):
                if np.isfinite(C[i, j]) and i != j and abs(C[i, j]) >= 0.5:
                    ax2.text(j, i, f"{C[i, j]:.2f}", ha="center", va="center", fontsize=6)
        cb2 = fig.colorbar(im2, ax=ax2, shrink=0.8, ticks=[-1, -0.5, 0, 0.5, 1])
        cb2.set_label("correlation (-)", fontsize=7)
        cb2.ax.tick_params(labelsize=7)
        ax2.set_title("correlations (from the claims' tolerances)", fontsize=8)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return fig
