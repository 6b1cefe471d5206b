"""Matplotlib figures of gmasim results.

Every function takes a mapping of column name -> 1-D array, as returned by the Python API
(``gmasim.sweep(...)``, ...) or read from the CSV files ``gmasim`` writes
(:func:`read_csv`), and returns a ``matplotlib.figure.Figure``. Axis labels carry units;
:func:`save` writes PNG and SVG.
"""
from __future__ import annotations

import pathlib
from typing import Mapping, Sequence

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

Columns = Mapping[str, np.ndarray]


def read_csv(path) -> dict:
    """A CSV written by gmasim (header row of names with units) as {name: ndarray}.

    Numeric columns become float arrays (empty cells NaN); text columns (status, law, rod)
    stay arrays of str."""
    import csv

    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    out = {}
    for j, name in enumerate(header):
        cells = [r[j] if j < len(r) else "" for r in body]
        try:
            out[name] = np.array([float(c) if c not in ("", "null") else np.nan for c in cells], dtype=float)
        except ValueError:
            out[name] = np.array(cells, dtype=str)
    return out


def save(fig, directory, stem: str) -> list[pathlib.Path]:
    directory = pathlib.Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    out = []
    for ext in ("png", "svg"):
        p = directory / f"{stem}.{ext}"
        fig.savefig(p, dpi=130, bbox_inches="tight")
        out.append(p)
    plt.close(fig)
    return out


def _temperature_colors(temps):
    temps = np.asarray(sorted(set(np.round(temps, 9))))
    norm = matplotlib.colors.Normalize(vmin=temps.min(), vmax=max(temps.max(), temps.min() + 1e-9))
    cmap = matplotlib.colormaps["coolwarm"]
    return temps, norm, cmap


def _plot_vs_temperature(ax, cols: Columns, y: str, groups, **style):
    """One line of cols[y] against temperature per (row mask, label) group."""
    for sel, label in groups:
        order = np.argsort(cols["temperature_C"][sel])
        ax.plot(cols["temperature_C"][sel][order], cols[y][sel][order], "o-", label=label, **style)


def hysteresis_loops(loops: Columns, title="Hysteresis loops coloured by temperature"):
    """y(I) loops; columns temperature_C, current_A, y_um."""
    temps, norm, cmap = _temperature_colors(loops["temperature_C"])
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for T in temps:
        sel = np.isclose(loops["temperature_C"], T)
        i, y = loops["current_A"][sel], loops["y_um"][sel]
        ax.plot(np.append(i, i[:1]), np.append(y, y[:1]), color=cmap(norm(T)), lw=1.4, label=f"{T:g} °C")
    sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, label="temperature (°C)")
    ax.set_xlabel("coil current I (A)")
    ax.set_ylabel("output displacement y (µm)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="upper left")
    return fig


def sweep_vs_temperature(sweep: Columns, frequency_Hz: float | None = None,
                         title="Stroke, hysteresis and flux density against temperature"):
    """Columns temperature_C, current_pp_A, frequency_Hz, stroke_um, hysteresis_um, B_pp_T."""
    f = sweep["frequency_Hz"]
    if frequency_Hz is None:
        frequency_Hz = float(np.min(f))
    sel_f = np.isclose(f, frequency_Hz)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.9))
    groups = [(sel_f & np.isclose(sweep["current_pp_A"], I), f"{I:g} A")
              for I in sorted(set(sweep["current_pp_A"][sel_f]))]
    for ax, key in zip(axes, ("stroke_um", "hysteresis_um", "B_pp_T")):
        _plot_vs_temperature(ax, sweep, key, groups)
    for ax, lab in zip(axes, ("stroke (µm)", "hysteresis (µm)", "flux density B, peak-to-peak (T)")):
        ax.set_xlabel("temperature (°C)")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
        ax.legend(title="current p-p", fontsize=8)
    fig.suptitle(f"{title} ({frequency_Hz:g} Hz)")
    fig.tight_layout()
    return fig


def bode(frf: Columns, title="Frequency response, current to displacement"):
    """Columns temperature_C, frequency_Hz, stepped_mag_um_per_A, stepped_phase_deg,
    linear_mag_um_per_A, linear_phase_deg (NaN where a method was not run)."""
    temps, norm, cmap = _temperature_colors(frf["temperature_C"])
    freq = frf["frequency_Hz"] if "frequency_Hz" in frf else frf["f_Hz"]
    fig, (am, ap) = plt.subplots(2, 1, figsize=(6.8, 6), sharex=True)
    for T in temps:
        sel = np.isclose(frf["temperature_C"], T)
        f = freq[sel]
        c = cmap(norm(T))
        if np.any(np.isfinite(frf["linear_mag_um_per_A"][sel])):
            am.loglog(f, frf["linear_mag_um_per_A"][sel], "-", color=c, label=f"{T:g} °C, linearised")
            ap.semilogx(f, frf["linear_phase_deg"][sel], "-", color=c)
        if np.any(np.isfinite(frf["stepped_mag_um_per_A"][sel])):
            am.loglog(f, frf["stepped_mag_um_per_A"][sel], "o", ms=3.5, mfc="none", color=c,
                      label=f"{T:g} °C, stepped sine")
            ap.semilogx(f, frf["stepped_phase_deg"][sel], "o", ms=3.5, mfc="none", color=c)
    am.axvline(1270, color="gray", ls=":", lw=1)
    am.text(1270, am.get_ylim()[0], " paper: 1270 Hz", color="gray", fontsize=7, va="bottom")
    am.set_ylabel("|Y/I| (µm/A)")
    ap.set_ylabel("phase (°)")
    ap.set_xlabel("frequency (Hz)")
    for ax in (am, ap):
        ax.grid(alpha=0.3, which="both")
    am.legend(fontsize=7)
    am.set_title(title)
    fig.tight_layout()
    return fig


def tracking_error(track: Columns, title="Closed-loop tracking error against temperature"):
    """Columns temperature_C, amplitude_um, frequency_Hz, error_rms_um."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    refs = sorted(set(zip(track["amplitude_um"], track["frequency_Hz"])), key=lambda r: (r[1], r[0]))
    _plot_vs_temperature(ax, track, "error_rms_um",
                         [(np.isclose(track["amplitude_um"], A) & np.isclose(track["frequency_Hz"], f),
                           f"{A:g} µm, {f:g} Hz") for A, f in refs])
    ax.set_xlabel("temperature (°C)")
    ax.set_ylabel("RMS tracking error (µm)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(title="reference", fontsize=8)
    return fig


def retention(ret: Columns, title="Stroke retention against temperature (10 Hz)"):
    """Columns current_pp_A, temperature_C, stroke_retention_pct."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    _plot_vs_temperature(ax, ret, "stroke_retention_pct",
                         [(np.isclose(ret["current_pp_A"], I), f"{I:g} A") for I in sorted(set(ret["current_pp_A"]))])
    ax.axhline(70, color="gray", ls=":", lw=1)
    ax.text(ax.get_xlim()[0], 70, " paper: ≈70 % at 150 °C", color="gray", fontsize=7, va="bottom")
    ax.set_xlabel("temperature (°C)")
    ax.set_ylabel("stroke / stroke at 20 °C (%)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(title="current p-p", fontsize=8)
    return fig


def params_vs_temperature(p: Columns, title="Model parameters against temperature (8 A, 10 Hz)"):
    """Columns temperature_C, rod (name), mu_r_mean, rho_ohm_m, M_peak_A_per_m, E_G_mean_GPa, E_t_GPa."""
    panels = [("mu_r_mean", "μ_G/μ0, mean (-)"), ("rho_ohm_m", "ρ_G (Ω m)"),
              ("M_peak_A_per_m", "M_G, peak (A/m)"), ("E_G_mean_GPa", "E_G, mean (GPa)"),
              ("E_t_GPa", "E_t (GPa)")]
    fig, axes = plt.subplots(1, 5, figsize=(17, 3.6))
    for ax, (key, lab) in zip(axes, panels):
        _plot_vs_temperature(ax, p, key, [(p["rod"] == rod, str(rod)) for rod in sorted(set(p["rod"]))], ms=3)
        ax.set_xlabel("temperature (°C)")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def ablation(ab: Columns, laws: Sequence[str] | None = None,
             title="Ablation: one temperature law frozen at 20 °C"):
    """Columns law, frequency_Hz, error_rms_um (or `laws` naming the rows in order)."""
    if laws is None:
        laws = list(ab["law"])
    freqs = sorted(set(ab["frequency_Hz"]))
    names = list(dict.fromkeys(laws))
    x = np.arange(len(names))
    w = 0.8 / max(len(freqs), 1)
    fig, ax = plt.subplots(figsize=(6.8, 4.2))
    for k, f in enumerate(freqs):
        vals = []
        for n in names:
            idx = [i for i, (law, ff) in enumerate(zip(laws, ab["frequency_Hz"])) if law == n and np.isclose(ff, f)]
            vals.append(ab["error_rms_um"][idx[0]] if idx else np.nan)
        ax.bar(x + (k - (len(freqs) - 1) / 2) * w, vals, w, label=f"{f:g} Hz")
    ax.set_xticks(x, names)
    ax.set_xlabel("law whose temperature dependence is frozen")
    ax.set_ylabel("RMS change of the output vs full model (µm)")
    ax.set_title(title)
    ax.grid(alpha=0.3, axis="y")
    ax.legend(title="excitation (6 A, 70 °C)", fontsize=8)
    return fig
