"""Matplotlib figures of gmasim results.

Every function takes a mapping of column name -> 1-D array, as returned by the Python API
(``gmasim.sweep(...)``, ...) or read from the CSV files ``gmasim`` writes
(:func:`read_csv`), and returns a ``matplotlib.figure.Figure``. Axis labels carry units;
:func:`save` writes PNG and SVG.
"""
from __future__ import annotations

import os
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


def read_meta(out, stem) -> dict:
    """The "meta" object of OUT/<stem>.json a gmasim command wrote ({} if there is none)."""
    import json

    p = pathlib.Path(out) / f"{stem}.json"
    return json.loads(p.read_text())["meta"] if p.exists() else {}


_SAVE_HOOKS = []


def add_save_hook(fn):
    """Registers fn(fig, stem), called by :func:`save` before a figure is written (e.g. the
    tests' :func:`gmasim.figure_check.problems` collector); returns fn (usable as a decorator)."""
    _SAVE_HOOKS.append(fn)
    return fn


def remove_save_hook(fn):
    if fn in _SAVE_HOOKS:
        _SAVE_HOOKS.remove(fn)


def save(fig, directory, stem: str) -> list[pathlib.Path]:
    """Writes directory/stem.png and .svg atomically. With GMASIM_FIGURE_CHECK=1 in the
    environment the figure is first checked (gmasim.figure_check: title, axis labels with units,
    no overlapping texts, no legend over a line) and not written if it fails."""
    for hook in list(_SAVE_HOOKS):
        hook(fig, stem)
    if os.environ.get("GMASIM_FIGURE_CHECK") == "1":
        from . import figure_check

        figure_check.check(fig, stem)
    directory = pathlib.Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    out = []
    for ext in ("png", "svg"):
        p = directory / f"{stem}.{ext}"
        # Atomic, like every gmasim output (docs/reliability.md): a temporary file beside the
        # target, then a rename; a killed run never leaves a truncated figure under its name.
        tmp = p.with_name(f".{p.name}.tmp.{os.getpid()}")
        try:
            fig.savefig(tmp, dpi=130, bbox_inches="tight", format=ext)
            os.replace(tmp, p)
        finally:
            if tmp.exists():
                tmp.unlink()
        out.append(p)
    plt.close(fig)
    return out


# ---- the paper's numbers beside ours (issue 7, item 6) ------------------------------------
# A claim row is one row of claims.json (`gmasim reproduce`): id, kind, paper, ours, pass,
# result and the condition (temperature_C, reference_temperature_C, current_pp_A,
# frequency_Hz, amplitude_um). Figures mark the paper's value as a diamond: green edge when
# the claim passes, red edge and the claim id when it fails.

PASS_COLOR, FAIL_COLOR, PAPER_COLOR = "#1a9641", "#d7191c", "#555555"


def read_claims(path) -> list[dict]:
    """The claim rows of a claims.json written by `gmasim reproduce`."""
    import json

    with open(path) as f:
        return json.load(f)["tables"]["claims"]["rows"]


def paper_claims() -> list[dict]:
    """The paper's numbers of the built-in claims (data/claims.toml) as claim rows without our
    values (``pass`` None): the single commands' figures mark them in grey."""
    from . import _gmasim

    return list(_gmasim.paper_claims())


def _claims_of(claims, kind, **cond):
    """Applicable claims of one kind whose condition matches every given value."""
    out = []
    for c in claims or ():
        if c.get("kind") != kind or c.get("result") == "n/a" or c.get("paper") is None:
            continue
        if all(c.get(k) is not None and np.isclose(c[k], v) for k, v in cond.items() if v is not None):
            out.append(c)
    return out


def _claim_color(claim):
    if claim.get("pass") is None:
        return PAPER_COLOR
    return PASS_COLOR if claim.get("pass") else FAIL_COLOR


def _mark_paper(ax, x, y, claim, label_text=None):
    """The paper's value of one claim at (x, y): a diamond, its edge the pass/fail colour (grey
    when the claim was not evaluated); a failing claim is labelled ✗ on the side of the point
    that faces the middle of the axes, so the label stays inside the panel."""
    if not (np.isfinite(x) and np.isfinite(y)):
        return
    col = _claim_color(claim)
    ax.plot([x], [y], "D", ms=7, mfc="white", mec=col, mew=1.8, zorder=5, gid="paper")
    states = getattr(ax.figure, "_gmasim_paper_states", set())
    states.add(claim.get("pass"))
    ax.figure._gmasim_paper_states = states  # the legend explains only the markers drawn
    if claim.get("pass") is False or label_text:
        def upper(v, lo, hi, log):
            return np.log(v) > 0.5 * (np.log(lo) + np.log(hi)) if log and v > 0 and lo > 0 else v > 0.5 * (lo + hi)

        right = upper(x, *ax.get_xlim(), ax.get_xscale() == "log")
        top = upper(y, *ax.get_ylim(), ax.get_yscale() == "log")
        ax.annotate(label_text or "✗", (x, y), xytext=(-5 if right else 5, -5 if top else 5),
                    textcoords="offset points", fontsize=6.5, color=col, ha="right" if right else "left",
                    va="top" if top else "bottom")


def _paper_legend(ax, claims=None):
    from matplotlib.lines import Line2D

    h, lab = ax.get_legend_handles_labels()
    kinds = getattr(ax.figure, "_gmasim_paper_states", None)
    if kinds is None:
        kinds = {c.get("pass") for c in claims} if claims else {True, False}
    for state, col, text in ((True, PASS_COLOR, "paper (claim passes)"), (False, FAIL_COLOR, "paper (claim fails, ✗)"),
                             (None, PAPER_COLOR, "paper")):
        if state in kinds:
            h.append(Line2D([], [], ls="", marker="D", mfc="white", mec=col, mew=1.8, gid="paper"))
            lab.append(text)
    return h, lab


def _legend_outside(ax, handles=None, labels=None, title=None, fontsize=7):
    """A legend to the right of the axes, where it cannot cover a line."""
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    return ax.legend(handles, labels, title=title, fontsize=fontsize, title_fontsize=fontsize,
                     loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)


def _finish_axes(ax, legend_title, claims, title=None, outside=True):
    """Grid and legend of a panel (with the paper's markers explained when claims are drawn),
    and its title if given. The legend sits outside the axes unless ``outside`` is False."""
    if title is not None:
        ax.set_title(title)
    ax.grid(alpha=0.3)
    h, lab = _paper_legend(ax, claims) if claims else ax.get_legend_handles_labels()
    if outside:
        _legend_outside(ax, h, lab, title=legend_title)
    else:
        ax.legend(h, lab, title=legend_title, fontsize=7, title_fontsize=7)


def _value_at(cols, y, **cond):
    sel = np.ones(len(cols["temperature_C"]), dtype=bool)
    for k, v in cond.items():
        sel &= np.isclose(cols[k], v)
    return float(np.mean(cols[y][sel])) if np.any(sel) else np.nan


def _temperature_colors(temps):
    temps = np.asarray(sorted(set(np.round(temps, 9))))
    norm = matplotlib.colors.Normalize(vmin=temps.min(), vmax=max(temps.max(), temps.min() + 1e-9))
    cmap = matplotlib.colormaps["coolwarm"]
    return temps, norm, cmap


_MARKERS = ("o", "s", "^", "h", "v", "P", "X")  # no diamond: it marks the paper's values
_LINESTYLES = ("-", "--", "-.", ":")


def _plot_vs_temperature(ax, cols: Columns, y: str, groups, **style):
    """One line of cols[y] against temperature per (row mask, label) group; each group its own
    marker and line style, later groups drawn thinner and on top, so coinciding lines stay
    distinguishable."""
    n = max(len(groups), 1)
    for k, (sel, label) in enumerate(groups):
        order = np.argsort(cols["temperature_C"][sel])
        kw = dict(marker=_MARKERS[k % len(_MARKERS)], ls=_LINESTYLES[k % len(_LINESTYLES)],
                  ms=max(7.0 - 4.0 * k / n, 3.0), lw=max(2.2 - 1.2 * k / n, 1.0), mfc="none" if k % 2 else None,
                  zorder=2 + k)
        kw.update(style)
        ax.plot(cols["temperature_C"][sel][order], cols[y][sel][order], label=label, **kw)


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
    ax.legend(fontsize=7, ncol=min(len(temps), 5), loc="upper center", bbox_to_anchor=(0.5, -0.14))
    return fig


def sweep_vs_temperature(sweep: Columns, frequency_Hz: float | None = None,
                         title="Stroke, hysteresis and flux density against temperature", claims=None):
    """Columns temperature_C, current_pp_A, frequency_Hz, stroke_um, hysteresis_um, B_pp_T.

    With `claims` (rows of claims.json), the paper's drops 20 -> 70 degC (Fig. 12-14) are
    marked at our 20 degC value times (1 - paper drop)."""
    f = sweep["frequency_Hz"]
    if frequency_Hz is None:
        frequency_Hz = float(np.min(f))
    sel_f = np.isclose(f, frequency_Hz)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.9))
    groups = [(sel_f & np.isclose(sweep["current_pp_A"], I), f"{I:g} A")
              for I in sorted(set(sweep["current_pp_A"][sel_f]))]
    for ax, key in zip(axes, ("stroke_um", "hysteresis_um", "B_pp_T")):
        _plot_vs_temperature(ax, sweep, key, groups)
    for ax, key, kind in zip(axes, ("stroke_um", "hysteresis_um", "B_pp_T"),
                             ("stroke_drop_pct", "hysteresis_drop_pct", "flux_drop_pct")):
        for c in _claims_of(claims, kind, frequency_Hz=frequency_Hz):
            ref = _value_at(sweep, key, temperature_C=c["reference_temperature_C"],
                            current_pp_A=c["current_pp_A"], frequency_Hz=frequency_Hz)
            _mark_paper(ax, c["temperature_C"], ref * (1.0 - c["paper"] / 100.0), c)
    for ax, lab in zip(axes, ("stroke (µm)", "hysteresis (µm)", "flux density B, peak-to-peak (T)")):
        ax.set_xlabel("temperature (°C)")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    _finish_axes(axes[-1], "current p-p", claims)
    fig.suptitle(f"{title} ({frequency_Hz:g} Hz)" + (
        "\n◇ the paper's change from 20 °C (Fig. 12-14), drawn on our 20 °C value" if claims else ""))
    fig.tight_layout()
    return fig


def bode(frf: Columns, title="Frequency response, current to displacement", claims=None, db=False,
         large_signal=False):
    """Columns temperature_C, frequency_Hz, stepped_mag_um_per_A, stepped_phase_deg,
    linear_mag_um_per_A, linear_phase_deg (NaN where a method was not run).

    The magnitude on a log axis in µm/A, or with `db` in dB re 1 µm/A (20 log10 |Y/I|). With
    `claims`, the paper's first resonance (Fig. 15) is marked on our curve at its
    temperature, and its bandwidth bound as a vertical line coloured pass/fail (grey when the
    claim was not evaluated). ``large_signal``: the linearised curves are labelled as the
    small-signal linearisation the stepped sine departs from. Legends sit outside the axes."""
    temps, norm, cmap = _temperature_colors(frf["temperature_C"])
    freq = frf["frequency_Hz"] if "frequency_Hz" in frf else frf["f_Hz"]
    fig, (am, ap) = plt.subplots(2, 1, figsize=(8.4, 6.2), sharex=True)

    def magnitude(m):
        return 20 * np.log10(m) if db else m

    plot_mag = am.semilogx if db else am.loglog
    lin_label = "small-signal linearisation" if large_signal else "linearised"
    for T in temps:
        sel = np.isclose(frf["temperature_C"], T)
        f = freq[sel]
        c = cmap(norm(T))
        if np.any(np.isfinite(frf["linear_mag_um_per_A"][sel])):
            plot_mag(f, magnitude(frf["linear_mag_um_per_A"][sel]), "--" if large_signal else "-", color=c,
                     lw=1.0 if large_signal else 1.5, label=f"{T:g} °C, {lin_label}")
            ap.semilogx(f, frf["linear_phase_deg"][sel], "--" if large_signal else "-", color=c)
        if np.any(np.isfinite(frf["stepped_mag_um_per_A"][sel])):
            plot_mag(f, magnitude(frf["stepped_mag_um_per_A"][sel]), "o-" if large_signal else "o", ms=3.5,
                     mfc="none", lw=0.8, color=c, label=f"{T:g} °C, stepped sine")
            ap.semilogx(f, frf["stepped_phase_deg"][sel], "o-" if large_signal else "o", ms=3.5, mfc="none",
                        lw=0.8, color=c)
    drawn = frf["stepped_mag_um_per_A"] if large_signal else frf["linear_mag_um_per_A"]
    mag = np.where(np.isfinite(drawn), drawn,
                   frf["linear_mag_um_per_A"] if large_signal else frf["stepped_mag_um_per_A"])
    for c in _claims_of(claims, "first_resonance_Hz"):
        sel = np.isclose(frf["temperature_C"], c["temperature_C"])
        if np.any(sel):
            order = np.argsort(freq[sel])
            y = float(np.interp(c["paper"], freq[sel][order], mag[sel][order]))
            _mark_paper(am, c["paper"], magnitude(y), c, None if c.get("pass") is False else
                        f"paper: {c['paper']:g} Hz")
    for c in _claims_of(claims, "bandwidth_Hz"):
        am.axvline(c["paper"], color=_claim_color(c), ls=":", lw=1.2,
                   label=f"paper: −3 dB bandwidth > {c['paper']:g} Hz" + (" ✗" if c.get("pass") is False else ""))
    am.set_ylabel("|Y/I| (dB re 1 µm/A)" if db else "|Y/I| (µm/A)")
    if not db:
        plain_log_axis(am, "y")
    ap.set_ylabel("phase (°)")
    ap.set_xlabel("frequency (Hz)")
    _log_frequency_axis(ap)
    for ax in (am, ap):
        ax.grid(alpha=0.3, which="both")
    _legend_outside(am, *(_paper_legend(am, _claims_of(claims, "first_resonance_Hz"))
                          if _claims_of(claims, "first_resonance_Hz") else (None, None)))
    am.set_title(title)
    fig.tight_layout()
    return fig


def _log_frequency_axis(ax):
    """Plain-number ticks on a log frequency axis (more per decade the fewer decades it spans), minor ticks unlabelled
    (matplotlib labels the minor ticks of an axis spanning less than a decade, and those overlap)."""
    plain_log_axis(ax, "x")


def plain_log_axis(ax, which: str = "y"):
    """Plain-number ticks on a log axis (x or y): 2, 5, 20, not 2×10^0, with more per decade the
    fewer decades it spans; minor ticks unlabelled."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    axis = ax.xaxis if which == "x" else ax.yaxis
    lo, hi = ax.get_xlim() if which == "x" else ax.get_ylim()
    lo, hi = min(lo, hi), max(lo, hi)
    decades = np.log10(hi / lo) if lo > 0 and hi > lo else 3.0
    subs = (1.0,) if decades > 1.6 else (1.0, 2.0, 5.0) if decades > 0.9 else (1.0, 1.5, 2.0, 3.0, 5.0, 7.0)
    axis.set_major_locator(LogLocator(base=10, subs=subs))
    axis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def tracking_error(track: Columns, title="Closed-loop tracking error against temperature", claims=None):
    """Columns temperature_C, amplitude_um, frequency_Hz, error_rms_um.

    With `claims`, the paper's error growth 20 -> 70 degC (Fig. 16) is marked at our 20 degC
    error times (1 + paper growth)."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    refs = sorted(set(zip(track["amplitude_um"], track["frequency_Hz"])), key=lambda r: (r[1], r[0]))
    _plot_vs_temperature(ax, track, "error_rms_um",
                         [(np.isclose(track["amplitude_um"], A) & np.isclose(track["frequency_Hz"], f),
                           f"{A:g} µm, {f:g} Hz") for A, f in refs])
    ax.set_xlabel("temperature (°C)")
    for c in _claims_of(claims, "track_error_growth_pct"):
        ref = _value_at(track, "error_rms_um", temperature_C=c["reference_temperature_C"],
                        amplitude_um=c["amplitude_um"], frequency_Hz=c["frequency_Hz"])
        _mark_paper(ax, c["temperature_C"], ref * (1.0 + c["paper"] / 100.0), c)
    ax.set_ylabel("RMS tracking error (µm)")
    _finish_axes(ax, "reference", claims, title)
    return fig


def retention(ret: Columns, title="Stroke retention against temperature (10 Hz)", claims=None):
    """Columns current_pp_A, temperature_C, stroke_retention_pct. With `claims`, the
    paper's retention (section 4.4.4) is marked per current."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    _plot_vs_temperature(ax, ret, "stroke_retention_pct",
                         [(np.isclose(ret["current_pp_A"], I), f"{I:g} A") for I in sorted(set(ret["current_pp_A"]))])
    marked = _claims_of(claims, "stroke_retention_pct")
    for paper, T in sorted({(c["paper"], c["temperature_C"]) for c in marked}):
        ax.axhline(paper, color="gray", ls=":", lw=1, label=f"paper: ≈{paper:g} % at {T:g} °C (Fig. 18)")
    for c in marked:
        _mark_paper(ax, c["temperature_C"], c["paper"], c)
    ax.set_xlabel("temperature (°C)")
    ax.set_ylabel("stroke / stroke at 20 °C (%)")
    _finish_axes(ax, "current p-p", claims, title)
    return fig


def params_vs_temperature(p: Columns, title="Model parameters against temperature (8 A, 10 Hz)", claims=None):
    """Columns temperature_C, rod (name), mu_r_mean, rho_ohm_m, M_peak_A_per_m, (MsT_A_per_m,)
    E_G_mean_GPa, E_t_GPa: a 2 x 3 grid, one quantity per panel, each defined in its title; ρ in
    µΩ m and M in kA/m (no offset labels). With `claims`, the paper's E_G rise (section 4.4.4)
    is marked at the rods' mean E_G at 20 degC times (1 + rise)."""
    panels = [("mu_r_mean", 1.0, "μ_G/μ0 (-)", "relative permeability, mean over the loop (eq. 3)"),
              ("rho_ohm_m", 1e6, "ρ_G (µΩ m)", "resistivity ρ_G (eq. 8)"),
              ("M_peak_A_per_m", 1e-3, "M_G, peak (kA/m)", "magnetisation, peak |M| over the loop"),
              ("MsT_A_per_m", 1e-3, "M_s^T (kA/m)", "saturation magnetisation M_s^T (eq. 4)"),
              ("E_G_mean_GPa", 1.0, "E_G (GPa)", "rod modulus E_G, mean over the loop (eq. 13)"),
              ("E_t_GPa", 1.0, "E_t (GPa)", "E_t: modulus of the steel sleeve (eq. 19)")]
    panels = [q for q in panels if q[0] in p]
    fig, axes = plt.subplots(2, 3, figsize=(12.5, 7.2))
    axes = axes.ravel()
    rods = sorted(set(p["rod"]))
    for ax, (key, scale, lab, what) in zip(axes, panels):
        scaled = dict(p)
        scaled[key] = np.asarray(p[key], dtype=float) * scale
        _plot_vs_temperature(ax, scaled, key, [(p["rod"] == rod, str(rod)) for rod in rods], ms=4)
        ax.set_xlabel("temperature (°C)")
        ax.set_ylabel(lab)
        ax.set_title(what, fontsize=9)
        ax.ticklabel_format(axis="y", useOffset=False, style="plain")
        ax.grid(alpha=0.3)
        if key == "E_G_mean_GPa":
            for c in _claims_of(claims, "EG_rise_pct"):
                ref = _value_at(p, "E_G_mean_GPa", temperature_C=c["reference_temperature_C"])
                _mark_paper(ax, c["temperature_C"], ref * (1.0 + c["paper"] / 100.0), c)
    for ax in axes[len(panels):]:
        fig.delaxes(ax)
    h, lab = axes[0].get_legend_handles_labels()
    if claims and _claims_of(claims, "EG_rise_pct"):
        h, lab = _paper_legend(axes[0], _claims_of(claims, "EG_rise_pct"))
        lab = [t if not t.startswith("paper") else t + ": E_G rise 20 → 150 °C, on our 20 °C mean" for t in lab]
    fig.legend(h, lab, loc="lower center", ncol=len(h), fontsize=8, bbox_to_anchor=(0.5, 0.0))
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig


# The ablated laws (gmasim ablate, docs/experiments.md) by the quantity each freezes.
LAW_LABELS = {"mu_G": "μ_G (eq. 3)", "rho_G": "ρ_G (eq. 8)", "M": "M_s^T (eq. 4)", "M_G": "M_G",
              "E_G": "E_G (eq. 13)", "E_t": "E_t (eq. 19)", "F_pm": "F_pm (eq. 1)", "all": "all laws"}


def ablation(ab: Columns, laws: Sequence[str] | None = None,
             title="Ablation: one temperature law frozen at 20 °C", condition="6 A, 70 °C"):
    """Columns law, frequency_Hz, error_rms_um and (when present) error_pct_of_stroke (or `laws`
    naming the rows in order). One panel: the RMS change of the output in µm on a log axis (the
    laws span six decades), the largest bar of each frequency labelled with its % of the stroke
    (the paper's unit); a law whose freeze changes nothing is marked 'exactly 0' where its bar
    would stand."""
    if laws is None:
        laws = list(ab["law"])
    freqs = sorted(set(ab["frequency_Hz"]))
    names = list(dict.fromkeys(laws))
    x = np.arange(len(names))
    w = 0.8 / max(len(freqs), 1)
    pct = ab.get("error_pct_of_stroke") if hasattr(ab, "get") else None
    fig, ax = plt.subplots(figsize=(8.6, 4.6))
    vals = {}
    for k, f in enumerate(freqs):
        v, p = [], []
        for n in names:
            idx = [i for i, (law, ff) in enumerate(zip(laws, ab["frequency_Hz"]))
                   if law == n and np.isclose(ff, f)]
            v.append(ab["error_rms_um"][idx[0]] if idx else np.nan)
            p.append(pct[idx[0]] if idx and pct is not None else np.nan)
        vals[f] = (np.asarray(v, float), np.asarray(p, float))
    positive = np.concatenate([v[v > 0] for v, _ in vals.values()]) if vals else np.array([])
    floor = 10 ** np.floor(np.log10(positive.min())) / 3 if positive.size else 1e-6
    for k, f in enumerate(freqs):
        v, p = vals[f]
        xs = x + (k - (len(freqs) - 1) / 2) * w
        ax.bar(xs, np.where(v > 0, v, np.nan), w, bottom=floor, label=f"{f:g} Hz")
    # The largest law's change in % of the stroke (the paper's unit), once above its group.
    first = np.array(vals[freqs[0]][0], float) if freqs else np.array([])
    first[[str(n) == "all" for n in names]] = np.nan  # the largest single law
    if first.size and np.any(np.isfinite(first)):
        top = int(np.nanargmax(first))
        p_top = [vals[f][1][top] for f in freqs]
        if all(np.isfinite(p_top)):
            peak = max(vals[f][0][top] for f in freqs)
            ax.annotate(" / ".join(f"{q:.1f}" for q in p_top) + " %\nof the stroke", (x[top], peak),
                        xytext=(0, 3), textcoords="offset points", ha="center", va="bottom",
                        fontsize=7)
    for j, n in enumerate(names):
        if all(vals[f][0][j] == 0 for f in freqs):
            ax.annotate("exactly 0\n(no drift\nin the model)" if str(n) == "F_pm" else "exactly 0",
                        (x[j], floor), xytext=(0, 4), textcoords="offset points", ha="center",
                        va="bottom", fontsize=7, color="0.3")
    ax.set_yscale("log")
    ax.set_ylim(floor, positive.max() * 8 if positive.size else 1.0)
    plain_log_axis(ax, "y")
    ax.set_xticks(x, [LAW_LABELS.get(str(n), str(n)) for n in names], fontsize=8,
                  rotation=60 if len(names) > 3 else 0, ha="right" if len(names) > 3 else "center",
                  rotation_mode="anchor")
    ax.set_xlabel("law whose temperature dependence is frozen")
    ax.set_ylabel("RMS change of the output (µm)")
    ax.grid(alpha=0.3, axis="y")
    _legend_outside(ax, title=f"excitation ({condition})")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def _claim_label(c, width=58):
    """A claim in words (its ``claim`` text, shortened), not its code identifier."""
    text = str(c.get("claim") or c.get("id", "")).replace("degC", "°C").replace(" -> ", " → ")
    text = text if len(text) <= width else text[:width - 1] + "…"
    return text + (" (fit)" if c.get("fitted") else "")


def _claim_value(v) -> str:
    """A claim's value as the report prints it: 4 significant digits."""
    return f"{v:.4g}"


def claims_overview(claims: Sequence[dict], title="The paper's claims: ours against the paper"):
    """One row per applicable claim of claims.json: ours / paper on a log axis (1 = the
    paper), green when the claim passes, red when it fails; a bound the paper states ("<
    0.17 %", "> 2000 Hz") is written as ours against the bound, and rankings without a number are
    listed with their result."""
    rows = [c for c in claims if c.get("result") != "n/a"]
    fig, ax = plt.subplots(figsize=(9.0, 0.26 * len(rows) + 1.4))
    y = np.arange(len(rows))[::-1]
    for yi, c in zip(y, rows):
        col = PASS_COLOR if c.get("pass") else FAIL_COLOR
        paper, ours = c.get("paper"), c.get("ours")
        rule = str(c.get("tolerance", ""))
        if rule.startswith(("ours <", "ours >")) and ours is not None and np.isfinite(ours):
            # A bound the paper states ("less than 0.17 %", "exceeds 2000 Hz"): ours against the
            # bound in words, not a ratio to it (a passing value far inside a bound is no miss).
            ax.text(1.0, yi, f" {_claim_value(ours)} {rule[5]} {c.get('paper'):g} {c.get('unit', '')}: "
                    f"{c.get('result')} (a bound)", color=col, fontsize=6.5, va="center")
            continue
        if paper is not None and ours is not None and np.isfinite(paper) and paper != 0 and np.isfinite(ours):
            r = ours / paper
            r = r if r > 0 else np.nan
            if np.isfinite(r):
                rc = min(max(r, 0.1), 10.0)  # off the axis: an arrow at its edge and the ratio
                ax.plot([1.0, rc], [yi, yi], "-", color=col, lw=1.2)
                ax.plot([rc], [yi], "o" if rc == r else (">" if r > 1 else "<"), color=col, ms=5)
                if rc != r:
                    ax.text(rc, yi + 0.25, f"×{r:.3g} ", color=col, fontsize=6.5, ha="right" if r > 1 else "left")
                continue
        rule = rule if len(rule) <= 40 else rule[:39] + "…"
        ax.text(1.0, yi, f" {c.get('result')}: {rule}", color=col, fontsize=6.5, va="center")
    ax.axvline(1.0, color="black", lw=0.8)
    ax.set_xscale("log")
    ax.set_xlim(0.1, 10.0)
    ax.set_yticks(y, [f"{'✓' if c.get('pass') else '✗'} {_claim_label(c)}" for c in rows], fontsize=7)
    for t, c in zip(ax.get_yticklabels(), rows):
        t.set_color(PASS_COLOR if c.get("pass") else FAIL_COLOR)
    npass = sum(1 for c in rows if c.get("pass"))
    ax.set_xlabel("ours / paper (log; 1 = the paper's number)")
    ax.set_ylabel("claim (✓ passes, ✗ fails)")
    ax.set_title(f"{title}: {npass} of {len(rows)} pass")
    ax.grid(alpha=0.3, axis="x", which="both")
    fig.tight_layout()
    return fig


# The sensitivity heatmap lives in its own module (file size); plots.sensitivity_heatmap stays.
from .sensitivity_figure import sensitivity_heatmap  # noqa: E402,F401
