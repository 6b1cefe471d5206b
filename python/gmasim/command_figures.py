"""The figure of one gmasim command, drawn from the files the command wrote (``--plot``).

    /usr/bin/python3 -m gmasim.command_figures COMMAND OUT_DIR

writes OUT_DIR/COMMAND.png and .svg (identify: overlay_<condition> and convergence), atomically
(:func:`gmasim.plots.save`). The C++ side writes only data; everything drawn here is read back
from those CSV and JSON files, so a figure can be redrawn later from a finished run.
"""
from __future__ import annotations

import json
import pathlib
import sys

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from gmasim import plots
from gmasim.design_figure import design
from gmasim.plots import plt, read_csv


_meta = plots.read_meta


def _window(ts, m):
    """The rows of the metrics window (the last whole period: no start-up branch)."""
    if "window_start_s" in m and m.get("window_end_s", 0) > m["window_start_s"]:
        keep = (ts["t_s"] >= m["window_start_s"] - 1e-12) & (ts["t_s"] <= m["window_end_s"] + 1e-12)
        if keep.sum() > 10:
            return {k: v[keep] for k, v in ts.items()}
    return ts


def _annotate_loop(ax, i, y, m):
    """The stroke (max - min of y) and the hysteresis (max |y_rising - y_falling| at equal
    current) as double arrows on the loop, with the values the metrics report."""
    k_lo, k_hi = int(np.argmin(y)), int(np.argmax(y))
    x_s = float(np.max(i)) + 0.04 * float(np.ptp(i) or 1.0)
    arrow = dict(arrowstyle="<->", color="black", lw=0.9, shrinkA=0, shrinkB=0)
    ax.annotate("", (x_s, y[k_lo]), xytext=(x_s, y[k_hi]), arrowprops=arrow)
    stroke = m.get("stroke_um", float(np.ptp(y)))
    ax.text(x_s, 0.5 * (y[k_lo] + y[k_hi]), f" stroke\n {stroke:.1f} µm", fontsize=7, va="center",
            ha="left")
    ax.set_xlim(ax.get_xlim()[0], x_s + 0.25 * float(np.ptp(i) or 1.0))
    di = np.diff(i)
    rising, falling = np.append(di > 0, di[-1:] > 0), np.append(di < 0, di[-1:] < 0)
    if rising.sum() > 2 and falling.sum() > 2:
        grid = np.linspace(max(i[rising].min(), i[falling].min()), min(i[rising].max(), i[falling].max()), 200)
        o_r, o_f = np.argsort(i[rising]), np.argsort(i[falling])
        yr = np.interp(grid, i[rising][o_r], y[rising][o_r])
        yf = np.interp(grid, i[falling][o_f], y[falling][o_f])
        k = int(np.argmax(np.abs(yr - yf)))
        ax.annotate("", (grid[k], yr[k]), xytext=(grid[k], yf[k]), arrowprops=dict(arrow, color="tab:red"))
        hyst = m.get("hysteresis_um", float(abs(yr[k] - yf[k])))
        ax.annotate(f"hysteresis {hyst:.1f} µm", (grid[k], 0.5 * (yr[k] + yf[k])), xytext=(6, 0),
                    textcoords="offset points", fontsize=7, color="tab:red", va="center")


def _self_heating_figure(ts, h, meta):
    """Drift under self-heating: the stroke's change and the output's offset drift (the mean of
    y, and the thermal expansion x_T when recorded), both in % of the stroke at the start, on
    one axis that includes 0, beside the temperatures."""
    fig, (ax_T, ax_d) = plt.subplots(1, 2, figsize=(11, 4.0))
    for col, lab in (("coil_C", "coil"), ("rods_C", "rods"), ("housing_C", "housing")):
        if col in h:
            ax_T.plot(h["t_s"], h[col], label=lab)
    ax_T.set_xlabel("time (s)")
    ax_T.set_ylabel("temperature (°C)")
    ax_T.set_title("temperatures")
    ax_T.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3)
    # Row 0 is the start, row 1 the virgin-curve step: the drift is measured from row 2.
    t, stroke = h["t_s"][2:], h["stroke_um"][2:]
    s0 = float(stroke[0]) if len(stroke) and stroke[0] else np.nan
    ax_d.plot(t, 100.0 * (stroke / s0 - 1.0), color="tab:red", label="stroke change")
    if "y_mean_um" in h and len(h["y_mean_um"]) > 2:
        # The run's own mean of y over each whole period (self_heating.csv's y_mean_um): an
        # average of the recorded samples over the rows' intervals, which need not be whole
        # periods, drew the oscillation of y as a band (issue 41).
        ym = h["y_mean_um"][2:]
        ax_d.plot(t, 100.0 * (ym - ym[0]) / s0, color="tab:blue", label="offset drift (mean y)")
    if "xT_um" in ts:
        ax_d.plot(ts["t_s"], 100.0 * (ts["xT_um"] - ts["xT_um"][0]) / s0, color="tab:purple", ls="--",
                  label="thermal expansion x_T")
    ax_d.axhline(0.0, color="black", lw=0.6)
    lo, hi = ax_d.get_ylim()
    ax_d.set_ylim(min(lo, -1.0), max(hi, 1.0))
    ax_d.set_xlabel("time (s)")
    ax_d.set_ylabel(f"change (% of the first stroke, {s0:.1f} µm)")
    ax_d.set_title("drift relative to the stroke")
    ax_d.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    for ax in (ax_T, ax_d):
        ax.grid(alpha=0.3)
    fig.suptitle(f"gmasim simulate, self-heating: {meta.get('model', '')}, from {meta.get('temperature_C', '')} °C")
    fig.tight_layout()
    return fig


def simulate(out):
    """simulate.png: y and the current against time, y against current and the rods' B-H over
    the metrics window (the last whole period, without the start-up branch; stroke and
    hysteresis annotated), B against time; with self-heating also self_heating.png."""
    ts_all = read_csv(pathlib.Path(out) / "timeseries.csv")
    meta = json.loads((pathlib.Path(out) / "metrics.json").read_text())
    m = meta.get("metrics") or {}
    ts = ts_all
    if "window_start_s" in m and m["window_end_s"] > m["window_start_s"]:
        # A long run: its time traces show the last few metrics windows, not a solid band.
        t0 = m["window_end_s"] - 3 * (m["window_end_s"] - m["window_start_s"])
        keep = ts["t_s"] >= t0
        if keep.sum() > 10:
            ts = {k: v[keep] for k, v in ts.items()}
    win = _window(ts_all, m)
    # What the loop panels show: the metrics window (issue 41: a waveform's whole run was titled
    # "last period").
    w0, w1 = m.get("window_start_s", 0.0), m.get("window_end_s", 0.0)
    if (meta.get("waveform") or {}).get("kind") == "biased_sine":
        span = "last period"
    elif w1 > w0 and len(win["t_s"]) < len(ts_all["t_s"]):
        span = f"metrics window {w0:g}-{w1:g} s"
    else:
        span = "whole run"
    heat = pathlib.Path(out) / "self_heating.csv"
    fig = plt.figure(figsize=(11, 7.2))
    ax_t = fig.add_subplot(2, 2, 1)
    ax_t.plot(ts["t_s"], ts["y_um"], lw=0.8)
    ax_t.set_xlabel("time (s)")
    ax_t.set_ylabel("displacement y (µm)")
    ax_t.set_title("y and current against time")
    ax_i = ax_t.twinx()
    ax_i.plot(ts["t_s"], ts["current_A"], color="tab:orange", lw=0.6, alpha=0.6)
    ax_i.set_ylabel("current (A)", color="tab:orange")
    ax_l = fig.add_subplot(2, 2, 2)
    ax_l.plot(win["current_A"], win["y_um"], lw=1.0)
    ax_l.set_xlabel("current (A)")
    ax_l.set_ylabel("displacement y (µm)")
    ax_l.set_title(f"y against current ({span})")
    _annotate_loop(ax_l, win["current_A"], win["y_um"], m)
    ax_b = fig.add_subplot(2, 2, 3)
    ax_b.plot(ts["t_s"], ts["B_T"], lw=0.8, color="tab:green")
    ax_b.set_xlabel("time (s)")
    ax_b.set_ylabel("flux density B (T)")
    ax_b.set_title("flux density against time")
    ax_h = fig.add_subplot(2, 2, 4)
    rods = sorted({n.split("_")[0] for n in win if n.startswith("rod") and n.endswith("_H_A_per_m")})
    for r in rods:
        ax_h.plot(win[f"{r}_H_A_per_m"] / 1e3, win[f"{r}_B_T"], lw=0.8, label=r)
    ax_h.set_xlabel("field H (kA/m)")
    ax_h.set_ylabel("rod flux density φ/A (T)")
    ax_h.set_title(f"rods' B-H ({span})")
    if rods:
        ax_h.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    for ax in fig.axes:
        ax.grid(alpha=0.3)
    sets = meta.get("set") or []
    temp = f"{meta.get('temperature_C', '')} °C"
    if heat.exists():  # the run started there; the rods warmed up by the metrics window
        h = read_csv(heat)
        temp = f"from {meta.get('temperature_C', '')} °C (rods at {h['rods_C'][-1]:.1f} °C at the end), self-heating"
    fig.suptitle(f"gmasim simulate: {meta.get('model', '')}, {temp}"
                 + (f"\nwith --set {', '.join(sets)}" if sets else ""), fontsize=10)
    fig.tight_layout()
    if not heat.exists():
        return fig
    return [("simulate", fig), ("self_heating", _self_heating_figure(ts_all, read_csv(heat), meta))]


def bode_db(out):
    """Bode plot, |Y/I| in µm/A on a log axis with plain-number ticks (as reproduce's FRF figure;
    it was in dB, issue 41). Every marker comes from the data drawn (frf_summary.csv:
    markers_from): the -3 dB line 3 dB below their |Y/I| at the lowest frequency, the first
    resonance and the bandwidth, one legend entry per temperature; the paper's 1270 Hz and
    > 2000 Hz as grey lines. The title says small or large signal (frf_summary: large_signal,
    the stimulus above small_signal_limit_A; docs/experiments.md)."""
    frf = read_csv(pathlib.Path(out) / "frf.csv")
    summ = read_csv(pathlib.Path(out) / "frf_summary.csv")
    meta = _meta(out, "frf")
    bias, amp = meta.get("bias_A"), meta.get("amplitude_A")
    large = "large_signal" in summ and bool(np.any(summ["large_signal"] == "true"))
    stepped = bool(meta.get("stepped_sine", True))
    if bias is not None and amp is not None:
        amp_text = f"±{amp:g} A" if amp >= 0.1 else f"±{amp * 1e3:g} mA"
        stim = (f"stimulus {amp_text}, " + ("large signal" if large else "small signal")
                if stepped else "small-signal linearisation")
        title = f"Frequency response about a {bias:g} A bias ({stim})"
    else:
        title = "Frequency response"
    fig = plots.bode(frf, title=title, db=False, large_signal=large)
    am = fig.axes[0]
    temps, norm, cmap = plots._temperature_colors(frf["temperature_C"])
    paper_f, paper_bw = meta.get("paper_first_resonance_Hz"), meta.get("paper_bandwidth_Hz_at_least")
    for T in temps:
        c = cmap(norm(T))
        s = np.isclose(summ["temperature_C"], T)
        if not np.any(s):
            continue
        g0 = summ["reference_gain_um_per_A"][s][0] if "reference_gain_um_per_A" in summ else \
            summ["static_gain_um_per_A"][s][0]
        fr = summ["first_resonance_Hz"][s][0]
        bw = summ["bandwidth_3dB_Hz"][s][0]
        src = summ["markers_from"][s][0] if "markers_from" in summ else "linearisation"
        parts = []
        if np.isfinite(g0) and g0 > 0:
            am.axhline(g0 * 10.0 ** (-3.0 / 20.0), color=c, ls=":", lw=0.8)
        if np.isfinite(fr) and fr > 0:
            am.axvline(fr, color=c, ls="--", lw=0.8)
            parts.append(f"peak {fr:.0f} Hz")
        if np.isfinite(bw) and bw > 0:
            am.axvline(bw, color=c, ls=":", lw=0.8)
            parts.append(f"−3 dB at {bw:.0f} Hz")
        am.plot([], [], ls="--", color=c, lw=0.8,
                label=f"{T:g} °C ({src}): " + (", ".join(parts) if parts else "no peak, no −3 dB point"))
    am.plot([], [], ls=":", color="0.4", lw=0.8, label="−3 dB below |Y/I| at the lowest frequency")
    if paper_f:
        am.axvline(paper_f, color=plots.PAPER_COLOR, ls="-", lw=2.5, alpha=0.35,
                   label=f"paper (Fig. 15): first resonance {paper_f:g} Hz")
    if paper_bw:
        xlim = am.get_xlim()
        am.axvspan(paper_bw, max(xlim[1], paper_bw), color=plots.PAPER_COLOR, alpha=0.08,
                   label=f"paper: −3 dB bandwidth > {paper_bw:g} Hz")
        am.set_xlim(xlim[0], max(xlim[1], 1.2 * paper_bw))
    # One legend under both panels, in two columns: beside them it took 40 % of the width.
    if am.get_legend():
        am.get_legend().remove()
    handles, labels = am.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=7, frameon=False)
    rows = (len(labels) + 1) // 2
    legend_in = 0.14 * rows + 0.12  # the legend's height [in] at 7 pt
    fig.set_size_inches(8.4, 6.2 + legend_in)
    fig.tight_layout(rect=(0, legend_in / (6.2 + legend_in), 1, 1))
    plots.plain_log_axis(am, "y")
    return fig


def sweep(out):
    """sweep.png with the paper's drops 20 -> 70 °C (Fig. 12-14) marked in grey where the sweep
    has both temperatures and the claim's current and frequency."""
    return plots.sweep_vs_temperature(read_csv(pathlib.Path(out) / "sweep.csv"), claims=plots.paper_claims())


def track(out):
    """track.png: the RMS tracking error against temperature per reference (the paper's growth
    20 -> 70 °C of Fig. 16 marked in grey on our 20 °C error), and the first point's run: the
    reference and y, and the error y - reference below them."""
    t = read_csv(pathlib.Path(out) / "track.csv")
    ex = read_csv(pathlib.Path(out) / "track_example.csv")
    meta = _meta(out, "track")
    fig = plt.figure(figsize=(12, 5.2))
    gs = fig.add_gridspec(2, 2, height_ratios=(2, 1))
    a = fig.add_subplot(gs[:, 0])
    b = fig.add_subplot(gs[0, 1])
    e = fig.add_subplot(gs[1, 1], sharex=b)
    refs = sorted(set(zip(t["amplitude_um"], t["frequency_Hz"])), key=lambda r: (r[1], r[0]))
    plots._plot_vs_temperature(a, t, "error_rms_um",
                               [(np.isclose(t["amplitude_um"], A) & np.isclose(t["frequency_Hz"], f),
                                 f"{A:g} µm, {f:g} Hz") for A, f in refs])
    claims = plots._claims_of(plots.paper_claims(), "track_error_growth_pct")
    marked = []
    for c in claims:
        ref = plots._value_at(t, "error_rms_um", temperature_C=c["reference_temperature_C"],
                              amplitude_um=c["amplitude_um"], frequency_Hz=c["frequency_Hz"])
        if np.isfinite(ref) and np.any(np.isclose(t["temperature_C"], c["temperature_C"])):
            plots._mark_paper(a, c["temperature_C"], ref * (1.0 + c["paper"] / 100.0), c)
            marked.append(c)
    a.set_xlabel("temperature (°C)")
    a.set_ylabel("RMS tracking error (µm)")
    a.set_title("RMS error over the last period")
    h, lab = plots._paper_legend(a, marked) if marked else a.get_legend_handles_labels()
    lab = [x + ": error growth 20 → 70 °C (Fig. 16) on our 20 °C error" if x == "paper" else x for x in lab]
    a.legend(h, lab, title="reference", fontsize=7, title_fontsize=7, loc="upper center",
             bbox_to_anchor=(0.5, -0.13), ncol=2)
    b.plot(ex["t_s"], ex["reference_um"], label="reference", lw=1.0)
    b.plot(ex["t_s"], ex["y_um"], label="output y", lw=1.0, ls="--")
    first = (f"{t['temperature_C'][0]:g} °C, {t['amplitude_um'][0]:g} µm, {t['frequency_Hz'][0]:g} Hz"
             if len(t["temperature_C"]) else "")
    b.set_title(f"first point ({first})")
    b.set_ylabel("displacement (µm)")
    b.tick_params(labelbottom=False)
    plots._legend_outside(b)
    err = ex["error_um"] if "error_um" in ex else ex["y_um"] - ex["reference_um"]
    e.plot(ex["t_s"], err, color="tab:red", lw=0.8)
    e.axhline(0.0, color="black", lw=0.5)
    e.set_xlabel("time (s)")
    e.set_ylabel("error (µm)")
    for ax in (a, b, e):
        ax.grid(alpha=0.3)
    gains = (f"PID kp {meta['kp_A_per_um']:g}, ki {meta['ki_A_per_um_per_sample_at_reference_rate']:g}, "
             f"kd {meta['kd_A_per_um_per_sample_at_reference_rate']:g}" if "kp_A_per_um" in meta else "PID")
    fig.suptitle(f"gmasim track: closed-loop tracking of a sine reference ({gains})")
    fig.tight_layout()
    return fig


_CONTROLLERS = {"pid": ("PID alone", "o"), "pid_temperature": ("PID + temperature feed-forward", "s"),
                "pid_inverse": ("PID + inverse-model feed-forward", "^")}


def track_feedforward(out):
    """``track --feedforward inverse``: RMS error on every mismatched plant (one panel per loop
    temperature, at the grid point the issue's goal names if present; a plant whose loop drove the
    current to its limit is ringed in red) and RMS(PID)/RMS(PID + feed-forward) against frequency
    (median, with error bars from the smallest to the largest ratio over the plants)."""
    t = read_csv(pathlib.Path(out) / "track.csv")
    q = read_csv(pathlib.Path(out) / "track_ratios.csv")
    temps = sorted(set(t["temperature_C"]))
    f0 = 100.0 if np.any(np.isclose(t["frequency_Hz"], 100.0)) else float(t["frequency_Hz"][0])
    A0 = 20.0 if np.any(np.isclose(t["amplitude_um"], 20.0)) else float(t["amplitude_um"][0])
    fig, axes = plt.subplots(1, len(temps) + 1, figsize=(4.2 * (len(temps) + 1), 4.6))
    labels = list(dict.fromkeys(t["mismatch"]))
    railed = (t["saturated"] == "true") if "saturated" in t else np.zeros(len(t["mismatch"]), bool)
    for ax, T in zip(axes, temps):
        for k, (c, (name, marker)) in enumerate(_CONTROLLERS.items()):
            sel = (t["controller"] == c) & np.isclose(t["temperature_C"], T) & \
                np.isclose(t["frequency_Hz"], f0) & np.isclose(t["amplitude_um"], A0)
            if sel.any():
                x = [labels.index(m) for m in t["mismatch"][sel]]
                # a colour per controller, the same in every panel (the rings take none of them)
                ax.semilogy(x, t["rms_error_um"][sel], marker, color=f"C{k}", label=name, alpha=0.8)
                # A loop that does not track: its current railed at the limit, or its error's RMS
                # exceeds the reference's own (A / sqrt 2: worse than no output at all).
                bad = sel & (railed | (t["rms_error_um"] > t["amplitude_um"] / np.sqrt(2.0)))
                if bad.any():
                    ax.semilogy([labels.index(m) for m in t["mismatch"][bad]], t["rms_error_um"][bad], "o",
                                ms=11, mfc="none", mec="red", mew=1.0,
                                label="no tracking: error above the reference's RMS, or current railed")
        ax.set_xticks(range(len(labels)))
        ax.set_xticklabels(labels, rotation=90, fontsize=6)
        ax.set_xlabel("plant (M_s, k, λ_s ±10 %, temperature ±10 °C)")
        ax.set_ylabel("RMS tracking error (µm)")
        plots.plain_log_axis(ax, "y")
        ax.set_title(f"loop at {T:g} °C, {A0:g} µm, {f0:g} Hz", fontsize=9)
        ax.grid(alpha=0.3, which="both")
    seen = {}
    for ax in axes[:-1]:
        for h, n in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(n, h)
    fig.legend(list(seen.values()), list(seen), loc="upper center", ncol=4, fontsize=8,
               bbox_to_anchor=(0.5, 0.95))
    r = axes[-1]
    sel_c = q["controller"] == "pid_inverse"
    freqs = []
    shift = {T: 1.0 + 0.04 * (k - (len(temps) - 1) / 2) for k, T in enumerate(temps)}  # side by side
    for T in temps:
        sel = sel_c & np.isclose(q["temperature_C"], T) & np.isclose(q["amplitude_um"], A0)
        if sel.any():
            f, med = q["frequency_Hz"][sel], q["ratio_median"][sel]
            freqs.extend(f)
            r.errorbar(f * shift[T], med, yerr=[med - q["ratio_min"][sel], q["ratio_max"][sel] - med], fmt="o-",
                       capsize=4, label=f"{T:g} °C: median, min..max")
    r.set_xscale("log")
    r.set_yscale("log")
    if freqs:  # the frequencies run, not decades around one point
        r.set_xlim(min(freqs) / 2.0, max(freqs) * 2.0)
    r.axhline(1.0, color="k", lw=0.8, label="1: no gain from the feed-forward")
    r.set_xlabel("reference frequency (Hz)")
    r.set_ylabel("RMS(PID) / RMS(PID + inverse) (-)")
    if r.lines:
        plots.plain_log_axis(r, "x")
        plots.plain_log_axis(r, "y")
    r.set_title(f"error ratio over the plants, {A0:g} µm", fontsize=9)
    r.grid(alpha=0.3, which="both")
    r.legend(fontsize=7, loc="best")
    fig.suptitle("Inverse-model feed-forward against plants that differ from the model")
    fig.tight_layout(rect=(0, 0, 1, 0.9))
    return fig


def compensate(out):
    """compensate.png: the solved drive (current p-p, its maximum and minimum) and the gain
    schedule g(T) against temperature, one legend for both axes; the stroke with and without the
    schedule against the target; with --track, the tracking errors with and without it."""
    s = read_csv(pathlib.Path(out) / "compensate.csv")
    meta = _meta(out, "compensate")
    trk = pathlib.Path(out) / "compensate_track.csv"
    fig, axes = plt.subplots(1, 3 if trk.exists() else 2, figsize=(16 if trk.exists() else 11.5, 4.4))
    a, b = axes[0], axes[1]
    a.plot(s["temperature_C"], s["current_pp_A"], "o-", label="solved current, peak to peak")
    a.plot(s["temperature_C"], s["current_max_A"], "s--", label="solved current, maximum")
    if "current_min_A" in s:
        a.plot(s["temperature_C"], s["current_min_A"], "v:", label="solved current, minimum")
    a.set_xlabel("temperature (°C)")
    a.set_ylabel("current (A)")
    a2 = a.twinx()
    a2.plot(s["temperature_C"], s["gain"], "k-.", marker="x", label="gain g(T) (right axis)")
    a2.set_ylabel("gain g(T) (-)")
    h1, l1 = a.get_legend_handles_labels()
    h2, l2 = a2.get_legend_handles_labels()
    a.legend(h1 + h2, l1 + l2, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    a.set_title("solved drive and gain schedule")
    b.plot(s["temperature_C"], s["uncompensated_stroke_um"], "o-", label="reference drive")
    b.plot(s["temperature_C"], s["stroke_um"], "s--", label="compensated drive")
    tgt = meta.get("target_stroke_um")
    if tgt is not None:
        b.axhline(tgt, color="gray", ls=":", label=f"target {tgt:.2f} µm")
    b.set_xlabel("temperature (°C)")
    b.set_ylabel("stroke (µm)")
    b.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3)
    b.set_title("stroke")
    if trk.exists():
        t = read_csv(trk)
        c = axes[2]
        for A, f in sorted(set(zip(t["amplitude_um"], t["frequency_Hz"]))):
            sel = np.isclose(t["amplitude_um"], A) & np.isclose(t["frequency_Hz"], f)
            line, = c.plot(t["temperature_C"][sel], t["error_rms_um_pid"][sel], "o--",
                           label=f"PID {A:g} µm {f:g} Hz")
            c.plot(t["temperature_C"][sel], t["error_rms_um_ff"][sel], "s-", color=line.get_color(),
                   label=f"PID + feed-forward {A:g} µm {f:g} Hz")
        c.set_xlabel("temperature (°C)")
        c.set_ylabel("RMS tracking error (µm)")
        c.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=1)
        c.set_title("tracking")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"gmasim compensate: a temperature-scheduled drive for a constant stroke ({meta.get('model', '')})")
    fig.tight_layout()
    return fig


def identify(out):
    """The figures of a fit report directory (`gmasim identify --report OUT`): per condition
    overlay_<condition>.png (measured against simulated: the loop over the compared samples
    and the record against time or sample), and convergence.png (best weighted RMS error
    against model evaluations). Yields (stem, figure) pairs."""
    out = pathlib.Path(out)
    rep = json.loads((out / "fit_report.json").read_text())
    for c in rep["conditions"]:
        if c["failed"]:
            continue
        o = read_csv(out / c["overlay"])
        # Columns: time or sample, drive (current or field), measured, simulated, compared, ...
        t_key, drive, measured, simulated = list(o)[:4]
        cmp = o["compared"] > 0.5
        unit = c.get("response_unit", "um")
        ylabel = "strain (ppm)" if unit == "ppm" else "displacement (µm)"
        flux = "measured_flux_T" in o and np.any(np.isfinite(o["measured_flux_T"]))
        fig, axes = plt.subplots(1, 3 if flux else 2, figsize=(16 if flux else 11, 4.2))
        a1, a2 = axes[0], axes[1]
        x = o[drive] / 1e3 if drive == "field_A_per_m" else o[drive]
        a1.plot(x[cmp], o[measured][cmp], ".", ms=2.5, label="measured")
        a1.plot(x[cmp], o[simulated][cmp], "-", lw=1.2, label="simulated")
        a1.set_xlabel({"current_A": "current (A)", "field_A_per_m": "field H (kA/m)"}.get(drive, drive))
        a1.set_ylabel(ylabel)
        a1.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=7)
        a1.set_title("loop (compared samples)")
        t = o[t_key]
        a2.plot(t, o[measured], ".", ms=2.0, label="measured")
        a2.plot(t, o[simulated], "-", lw=1.0, label="simulated")
        if np.any(cmp) and np.argmax(cmp) > 0:  # only when leading samples are skipped
            a2.axvspan(t[0], t[np.argmax(cmp)], color="0.9", label="not compared")
        a2.set_xlabel("time (s)" if t_key == "t_s" else "sample (-)")
        a2.set_ylabel(ylabel)
        a2.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3, fontsize=7)
        a2.set_title("record")
        if flux:
            a3 = axes[2]
            a3.plot(t, o["measured_flux_T"], ".", ms=2.0, label="measured")
            a3.plot(t, o["simulated_flux_T"], "-", lw=1.0, label="simulated")
            a3.set_xlabel("time (s)" if t_key == "t_s" else "sample (-)")
            a3.set_ylabel("flux density B (T)")
            a3.set_title("flux")
            a3.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=7)
        for ax in axes:
            ax.xaxis.set_major_locator(MaxNLocator(nbins=5))
            ax.grid(alpha=0.3)
        freq = c["frequency_Hz"]
        cond = f'{c["temperature_C"]:g} °C' + (f', {c["current_pp_A"]:g} A p-p, {freq:g} Hz' if freq else "")
        fig.suptitle(f'{c["label"]}: {cond}; RMS {c.get("rms_" + unit, c.get("rms_um", float("nan"))):.3f} {"µm" if unit == "um" else unit} '
                     f'= {c["rms_pct"]:.2f} % of p-p')
        fig.tight_layout()
        yield pathlib.Path(c["overlay"]).stem, fig
    h = read_csv(out / "convergence.csv")
    if len(h["step"]):
        fig, ax = plt.subplots(figsize=(7, 4.2))
        for phase, style in (("ga", "o-"), ("refine", "s-")):
            sel = h["phase"] == phase
            if np.any(sel):
                ax.semilogy(h["evaluations"][sel], h["best_rms_pct"][sel], style, ms=3, label=phase)
        ax.set_xlabel("model evaluations (all ranks)")
        ax.set_ylabel("best weighted RMS error (%)")
        plots.plain_log_axis(ax, "y")
        ax.set_title(f"gmasim identify: convergence ({rep.get('model', '')})" if rep.get("model")
                     else "gmasim identify: convergence")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        yield "convergence", fig


def ablate(out):
    meta = _meta(out, "ablate")
    cond = (f"{meta['current_pp_A']:g} A, {meta['temperature_C']:g} °C"
            if "current_pp_A" in meta and "temperature_C" in meta else "")
    return plots.ablation(read_csv(pathlib.Path(out) / "ablate.csv"), condition=cond,
                          title=f"Ablation: one temperature law frozen at {meta.get('frozen_at_C', 20):g} °C")


def params(out):
    return plots.params_vs_temperature(read_csv(pathlib.Path(out) / "params.csv"))


def sensitivity(out):
    """The heatmap of sensitivity.json (per tolerance; rows without one per 10 % of their
    value) beside the correlations of identifiability.json."""
    out = pathlib.Path(out)
    doc = json.loads((out / "sensitivity.json").read_text())
    params = [p["name"] for p in doc["parameters"]]
    quants = [q["name"] for q in doc["quantities"]]
    S = np.full((len(quants), len(params)), np.nan)
    flags = np.full(S.shape, "ok", dtype=object)
    relative = []
    for i, q in enumerate(doc["quantities"]):
        scale = q["scale"]
        relative.append(scale is None)
        if scale is None and q["value"] not in (None, 0):
            scale = 0.1 * abs(q["value"])
        for j, p in enumerate(params):
            e = doc["entries"][q["name"]][p]
            if e["scaled"] is not None and scale:
                S[i, j] = e["scaled"] / scale
            flags[i, j] = e["flag"]
    ident = out / "identifiability.json"
    corr = None
    if ident.exists():
        corr = np.array([[np.nan if v is None else v for v in row]
                         for row in json.loads(ident.read_text())["correlation"]], dtype=float)
    return plots.sensitivity_heatmap(quants, params, S, flags=flags, correlation=corr,
                                     relative_rows=relative,
                                     title=f"gmasim sensitivity: {doc.get('model', '')}")


# A renderer returns the command's figure (saved as OUT/<command>.png|svg) or yields
# (stem, figure) pairs (OUT/<stem>.png|svg), each saved and closed before the next is drawn.
RENDERERS = {"simulate": simulate, "frf": bode_db, "sweep": sweep, "track": track,
             "track_feedforward": track_feedforward,
             "compensate": compensate, "ablate": ablate, "params": params, "identify": identify,
             "sensitivity": sensitivity, "design": design}


def render(command: str, out) -> list[pathlib.Path]:
    if command not in RENDERERS:
        raise SystemExit(f"gmasim.command_figures: no figure for '{command}' "
                         f"(known: {', '.join(sorted(RENDERERS))})")
    figures = RENDERERS[command](out)
    if isinstance(figures, Figure):
        figures = [(command, figures)]
    return [p for stem, fig in figures for p in plots.save(fig, out, stem)]


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        print("usage: python3 -m gmasim.command_figures COMMAND OUT_DIR", file=sys.stderr)
        return 1
    try:
        files = render(argv[0], argv[1])
    except (OSError, KeyError, ValueError) as e:
        print(f"gmasim.command_figures: {argv[0]} in {argv[1]}: {e}", file=sys.stderr)
        return 2
    del files
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
