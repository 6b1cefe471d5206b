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

from gmasim import plots
from gmasim.plots import plt, read_csv


def _meta(out, stem):
    p = pathlib.Path(out) / f"{stem}.json"
    return json.loads(p.read_text())["meta"] if p.exists() else {}


def simulate(out):
    ts = read_csv(pathlib.Path(out) / "timeseries.csv")
    meta = json.loads((pathlib.Path(out) / "metrics.json").read_text())
    m = meta.get("metrics") or {}
    if "window_start_s" in m and m["window_end_s"] > m["window_start_s"]:
        # A long run: its time traces show the last few metrics windows, not a solid band.
        t0 = m["window_end_s"] - 3 * (m["window_end_s"] - m["window_start_s"])
        keep = ts["t_s"] >= t0
        if keep.sum() > 10:
            ts = {k: v[keep] for k, v in ts.items()}
    heat = pathlib.Path(out) / "self_heating.csv"
    rows = 3 if heat.exists() else 2
    fig = plt.figure(figsize=(10, 3.4 * rows))
    ax_t = fig.add_subplot(rows, 2, 1)
    ax_t.plot(ts["t_s"], ts["y_um"], lw=0.8)
    ax_t.set_xlabel("time (s)")
    ax_t.set_ylabel("displacement y (µm)")
    ax_i = ax_t.twinx()
    ax_i.plot(ts["t_s"], ts["current_A"], color="tab:orange", lw=0.6, alpha=0.6)
    ax_i.set_ylabel("current (A)", color="tab:orange")
    ax_l = fig.add_subplot(rows, 2, 2)
    ax_l.plot(ts["current_A"], ts["y_um"], lw=0.8)
    ax_l.set_xlabel("current (A)")
    ax_l.set_ylabel("displacement y (µm)")
    ax_l.set_title("y against current")
    ax_b = fig.add_subplot(rows, 2, 3)
    ax_b.plot(ts["t_s"], ts["B_T"], lw=0.8, color="tab:green")
    ax_b.set_xlabel("time (s)")
    ax_b.set_ylabel("flux density B (T)")
    ax_h = fig.add_subplot(rows, 2, 4)
    rods = sorted({n.split("_")[0] for n in ts if n.startswith("rod") and n.endswith("_H_A_per_m")})
    for r in rods:
        ax_h.plot(ts[f"{r}_H_A_per_m"] / 1e3, ts[f"{r}_B_T"], lw=0.8, label=r)
    ax_h.set_xlabel("field H (kA/m)")
    ax_h.set_ylabel("rod flux density φ/A (T)")
    ax_h.legend(fontsize=7)
    if heat.exists():
        h = read_csv(heat)
        ax_T = fig.add_subplot(rows, 2, 5)
        for col, lab in (("coil_C", "coil"), ("rods_C", "rods"), ("housing_C", "housing")):
            ax_T.plot(h["t_s"], h[col], label=lab)
        ax_T.set_xlabel("time (s)")
        ax_T.set_ylabel("temperature (°C)")
        ax_T.legend(fontsize=7)
        ax_T.set_title("self-heating")
        ax_s = fig.add_subplot(rows, 2, 6)
        # Row 0 is the start, row 1 the virgin-curve step: the drift is drawn from row 2.
        ax_s.plot(h["t_s"][2:], h["stroke_um"][2:], color="tab:red")
        ax_s.set_xlabel("time (s)")
        ax_s.set_ylabel("stroke over the interval (µm)")
        ax_s.set_title("stroke drift")
    for ax in fig.axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"gmasim simulate: {meta.get('model', '')}, {meta.get('temperature_C', '')} °C"
                 + (", self-heating" if heat.exists() else ""))
    fig.tight_layout()
    return fig


def bode_db(out):
    """Bode plot in dB (re 1 µm/A) with the first resonance and the -3 dB bandwidth marked,
    and the stimulus (bias, amplitude) in the title."""
    frf = read_csv(pathlib.Path(out) / "frf.csv")
    summ = read_csv(pathlib.Path(out) / "frf_summary.csv")
    meta = _meta(out, "frf")
    bias, amp = meta.get("bias_A"), meta.get("amplitude_A")
    title = (f"Frequency response about a {bias:g} A bias, stimulus ±{amp * 1e3:g} mA (small signal)\n"
             "(dotted horizontal: static gain -3 dB)" if bias is not None and amp is not None
             else "Frequency response")
    fig = plots.bode(frf, title=title, db=True)
    am = fig.axes[0]
    temps, norm, cmap = plots._temperature_colors(frf["temperature_C"])
    for T in temps:
        c = cmap(norm(T))
        s = np.isclose(summ["temperature_C"], T)
        if not np.any(s):
            continue
        g0 = summ["static_gain_um_per_A"][s][0]
        fr = summ["first_resonance_Hz"][s][0]
        bw = summ["bandwidth_3dB_Hz"][s][0]
        if np.isfinite(g0) and g0 > 0:
            am.axhline(20 * np.log10(g0) - 3, color=c, ls=":", lw=0.8)
        if np.isfinite(fr) and fr > 0:
            am.axvline(fr, color=c, ls="--", lw=0.8)
            am.annotate(f"resonance {fr:.0f} Hz", (fr, am.get_ylim()[1]), color=c, fontsize=7,
                        rotation=90, va="top", ha="right")
        if np.isfinite(bw) and bw > 0:
            am.axvline(bw, color=c, ls=":", lw=0.8)
            am.annotate(f"-3 dB {bw:.0f} Hz", (bw, am.get_ylim()[0]), color=c, fontsize=7,
                        rotation=90, va="bottom", ha="right")
    fig.tight_layout()
    return fig


def sweep(out):
    return plots.sweep_vs_temperature(read_csv(pathlib.Path(out) / "sweep.csv"))


def track(out):
    t = read_csv(pathlib.Path(out) / "track.csv")
    ex = read_csv(pathlib.Path(out) / "track_example.csv")
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    refs = sorted(set(zip(t["amplitude_um"], t["frequency_Hz"])))
    for A, f in refs:
        sel = np.isclose(t["amplitude_um"], A) & np.isclose(t["frequency_Hz"], f)
        a.plot(t["temperature_C"][sel], t["error_rms_um"][sel], "o-", label=f"{A:g} µm, {f:g} Hz")
    a.set_xlabel("temperature (°C)")
    a.set_ylabel("RMS tracking error (µm)")
    a.legend(fontsize=7)
    b.plot(ex["t_s"], ex["reference_um"], label="reference")
    b.plot(ex["t_s"], ex["y_um"], label="y")
    b.set_xlabel("time (s)")
    b.set_ylabel("displacement (µm)")
    b.set_title("first point")
    b.legend(fontsize=7)
    for ax in (a, b):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


_CONTROLLERS = {"pid": ("PID alone", "o"), "pid_temperature": ("PID + temperature feed-forward", "s"),
                "pid_inverse": ("PID + inverse-model feed-forward", "^")}


def track_feedforward(out):
    """``track --feedforward inverse``: RMS error on every mismatched plant (one panel per loop
    temperature, at the grid point the issue's goal names if present) and RMS(PID)/RMS(PID +
    feed-forward) against frequency (median, with the min..max range)."""
    t = read_csv(pathlib.Path(out) / "track.csv")
    q = read_csv(pathlib.Path(out) / "track_ratios.csv")
    temps = sorted(set(t["temperature_C"]))
    f0 = 100.0 if np.any(np.isclose(t["frequency_Hz"], 100.0)) else float(t["frequency_Hz"][0])
    A0 = 20.0 if np.any(np.isclose(t["amplitude_um"], 20.0)) else float(t["amplitude_um"][0])
    fig, axes = plt.subplots(1, len(temps) + 1, figsize=(4.2 * (len(temps) + 1), 4.6))
    labels = list(dict.fromkeys(t["mismatch"]))
    for ax, T in zip(axes, temps):
        for c, (name, marker) in _CONTROLLERS.items():
            sel = (t["controller"] == c) & np.isclose(t["temperature_C"], T) & \
                np.isclose(t["frequency_Hz"], f0) & np.isclose(t["amplitude_um"], A0)
            if sel.any():
                x = [labels.index(m) for m in t["mismatch"][sel]]
                ax.semilogy(x, t["rms_error_um"][sel], marker, label=name, alpha=0.8)
        ax.set_xticks(range(len(labels)))
        ax.set_xticklabels(labels, rotation=90, fontsize=6)
        ax.set_xlabel("plant (M_s, k, λ_s ±10 %, temperature ±10 °C)")
        ax.set_ylabel("RMS tracking error (µm)")
        ax.set_title(f"loop at {T:g} °C, {A0:g} µm, {f0:g} Hz", fontsize=9)
        ax.grid(alpha=0.3, which="both")
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="upper center", ncol=3, fontsize=8, bbox_to_anchor=(0.5, 0.95))
    r = axes[-1]
    sel_c = q["controller"] == "pid_inverse"
    for T in temps:
        sel = sel_c & np.isclose(q["temperature_C"], T) & np.isclose(q["amplitude_um"], A0)
        if sel.any():
            f = q["frequency_Hz"][sel]
            line, = r.loglog(f, q["ratio_median"][sel], "o-", label=f"{T:g} °C median")
            r.fill_between(f, q["ratio_min"][sel], q["ratio_max"][sel], color=line.get_color(),
                           alpha=0.15)
    r.axhline(5.0, color="k", ls="--", lw=0.8, label="goal: median 5")
    r.axhline(2.0, color="k", ls=":", lw=0.8, label="goal: min 2")
    r.set_xlabel("reference frequency (Hz)")
    r.set_ylabel("RMS(PID) / RMS(PID + inverse) (-)")
    r.set_title(f"error ratio over the plants, {A0:g} µm (band: min..max)", fontsize=9)
    r.grid(alpha=0.3, which="both")
    r.legend(fontsize=7)
    fig.suptitle("Inverse-model feed-forward against plants that differ from the model")
    fig.tight_layout(rect=(0, 0, 1, 0.9))
    return fig


def compensate(out):
    s = read_csv(pathlib.Path(out) / "compensate.csv")
    meta = _meta(out, "compensate")
    trk = pathlib.Path(out) / "compensate_track.csv"
    fig, axes = plt.subplots(1, 3 if trk.exists() else 2, figsize=(15 if trk.exists() else 10, 4))
    a, b = axes[0], axes[1]
    a.plot(s["temperature_C"], s["current_pp_A"], "o-", label="current p-p")
    a.plot(s["temperature_C"], s["current_max_A"], "s--", label="current max")
    a.set_xlabel("temperature (°C)")
    a.set_ylabel("current (A)")
    a2 = a.twinx()
    a2.plot(s["temperature_C"], s["gain"], "k:", label="gain")
    a2.set_ylabel("gain (-)")
    a.legend(fontsize=7, loc="upper left")
    a.set_title("gain schedule")
    b.plot(s["temperature_C"], s["uncompensated_stroke_um"], "o-", label="reference drive")
    b.plot(s["temperature_C"], s["stroke_um"], "s-", label="compensated")
    tgt = meta.get("target_stroke_um")
    if tgt is not None:
        b.axhline(tgt, color="gray", ls=":", label=f"target {tgt:.2f} µm")
    b.set_xlabel("temperature (°C)")
    b.set_ylabel("stroke (µm)")
    b.legend(fontsize=7)
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
        c.legend(fontsize=6)
        c.set_title("tracking")
    for ax in axes:
        ax.grid(alpha=0.3)
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
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
        a1.plot(o[drive][cmp], o[measured][cmp], ".", ms=2.5, label="measured")
        a1.plot(o[drive][cmp], o[simulated][cmp], "-", lw=1.2, label="simulated")
        a1.set_xlabel({"current_A": "current (A)", "field_A_per_m": "field H (A/m)"}.get(drive, drive))
        a1.set_ylabel(ylabel)
        a1.legend(loc="upper left")
        a1.set_title("loop (compared samples)")
        t = o[t_key]
        a2.plot(t, o[measured], ".", ms=2.0, label="measured")
        a2.plot(t, o[simulated], "-", lw=1.0, label="simulated")
        if np.any(cmp) and np.argmax(cmp) > 0:  # only when leading samples are skipped
            a2.axvspan(t[0], t[np.argmax(cmp)], color="0.9", label="not compared")
        a2.set_xlabel("time (s)" if t_key == "t_s" else "sample (-)")
        a2.set_ylabel(ylabel)
        a2.legend(loc="upper left")
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
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        yield "convergence", fig


def ablate(out):
    return plots.ablation(read_csv(pathlib.Path(out) / "ablate.csv"))


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
             "sensitivity": sensitivity}


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
