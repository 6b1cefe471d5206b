#!/usr/bin/env python3
"""Four controllers on one reference, in the time domain (issue 40, item 4; docs/experiments.md,
"Your controller in the loop"): the paper's PID, the PID with the temperature schedule, the PID
with the inverse-model feed-forward, and a controller written here in Python -- the PID plus a
static inverse whose gain the controller measures with gmasim.simulate at the loop's
temperature.

    PYTHONPATH=build/ci/python /usr/bin/python3 examples/user_controller/compare_controllers.py \\
        [--temperature 70] [--amplitude 10] [--frequency 100] [--out DIR]

All four run on the built-in model (the plant is the model: no mismatch) at one temperature,
tracking y_bias + A sin(2 pi f t) at 10 kHz. It prints each one's absolute RMS and peak error
over the last period beside its ratio to the PID's, and writes compare_controllers.png: the
reference and the four responses, the errors, and the coil currents against time.
"""
from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np


class PidWithStaticInverse:
    """The paper's PID (gains per sample at 10 kHz, 0.5 A per unit about the 1 A bias) plus a
    static inverse (r - y_bias) / K(T), K the actuator's large-signal gain at the loop's
    temperature, which the controller measures itself with gmasim.simulate: the stroke of a
    +-1 A, 10 Hz sine about the bias over its current p-p [um/A]. (The small-signal DC gain of
    gmasim.linearize is 3-5x smaller -- the JA law's irreversible part is missing from it -- and
    would overdrive the loop.) y_bias is the reference at the first sample (the reference starts
    at its centre)."""

    def __init__(self, model, kp=0.2, ki=0.03, kd=0.007, bias_A=1.0, a=0.5, limit_A=10.0):
        import gmasim

        self.model, self.kp, self.ki, self.kd, self.bias_A, self.a = model, kp, ki, kd, bias_A, a
        self.u_min, self.u_max = (-limit_A - bias_A) / a, (limit_A - bias_A) / a
        self._simulate = gmasim.simulate
        self._K = {}
        self.reset()

    def reset(self):
        self.sum, self.e_prev, self.first, self.y_bias = 0.0, 0.0, True, None

    def gain_um_per_A(self, temperature_C):
        if temperature_C not in self._K:
            r = self._simulate(self.model, temperature_C=temperature_C, current_pp_A=2.0,
                               current_min_A=self.bias_A - 1.0, frequency_Hz=10.0)
            self._K[temperature_C] = r["metrics"]["stroke_um"] / 2.0
        return self._K[temperature_C]

    def __call__(self, reference_um, measured_um, temperature_C):
        if self.y_bias is None:
            self.y_bias = reference_um
        e = reference_um - measured_um
        de = 0.0 if self.first else e - self.e_prev
        self.first, self.e_prev = False, e
        sum_new = self.sum + e
        u_raw = self.kp * e + self.ki * sum_new + self.kd * de
        u = min(max(u_raw, self.u_min), self.u_max)
        if not ((u_raw > self.u_max and e > 0) or (u_raw < self.u_min and e < 0)):
            self.sum = sum_new
        return self.bias_A + self.a * u + (reference_um - self.y_bias) / self.gain_um_per_A(temperature_C)


LABELS = {"pid": "PID", "pid_temperature": "PID + temperature schedule",
          "pid_inverse": "PID + inverse feed-forward", "user": "your controller: PID + static inverse"}


def run(model, temperature_C, amplitude_um, frequency_Hz):
    """{name: the track result} of the four controllers on the same reference."""
    import gmasim

    grid = dict(temperatures_C=[temperature_C], amplitudes_um=[amplitude_um],
                frequencies_Hz=[frequency_Hz], threads=1)
    out = {name: gmasim.track(model, **grid, controller=name)
           for name in ("pid", "pid_temperature", "pid_inverse")}
    out["user"] = gmasim.track(model, **grid, controller=PidWithStaticInverse(model))
    return out


def figure(results, temperature_C, amplitude_um, frequency_Hz):
    import matplotlib.pyplot as plt

    fig, (ax_y, ax_e, ax_i) = plt.subplots(3, 1, figsize=(10, 8.2), sharex=True,
                                            gridspec_kw={"height_ratios": (2, 1.4, 1.4)})
    ref = results["pid"]["example"]
    t_ms = np.asarray(ref["t_s"]) * 1e3
    ax_y.plot(t_ms, ref["reference_um"], color="black", lw=2.2, alpha=0.35, label="reference")
    styles = {"pid": ("tab:red", "-"), "pid_temperature": ("tab:orange", "--"),
              "pid_inverse": ("tab:blue", "-"), "user": ("tab:green", ":")}
    for name, r in results.items():
        ex, (color, ls) = r["example"], styles[name]
        e_rms = r["points"]["error_rms_um"][0]
        label = f"{LABELS[name]} (RMS error {e_rms:.3f} µm)"
        ax_y.plot(t_ms, ex["y_um"], color=color, ls=ls, lw=1.0, label=label)
        ax_e.plot(t_ms, ex["error_um"], color=color, ls=ls, lw=1.0)
        ax_i.plot(t_ms, ex["current_A"], color=color, ls=ls, lw=1.0)
    ax_y.set_ylabel("displacement (µm)")
    ax_e.set_ylabel("error r − y (µm)")
    ax_i.set_ylabel("coil current (A)")
    ax_i.set_xlabel("time (ms)")
    ax_e.axhline(0.0, color="black", lw=0.5)
    for ax in (ax_y, ax_e, ax_i):
        ax.grid(alpha=0.3)
    ax_y.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.suptitle(f"Four controllers on one reference: {amplitude_um:g} µm at {frequency_Hz:g} Hz, "
                 f"{temperature_C:g} °C, built-in model (sampled at 10 kHz)")
    fig.tight_layout()
    return fig


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--temperature", type=float, default=70.0, help="loop temperature (degC)")
    ap.add_argument("--amplitude", type=float, default=10.0, help="reference amplitude (um)")
    ap.add_argument("--frequency", type=float, default=100.0, help="reference frequency (Hz)")
    ap.add_argument("--out", default="out/compare_controllers", help="directory of the figure")
    a = ap.parse_args(argv)
    import gmasim
    from gmasim import plots

    model = gmasim.Model()
    results = run(model, a.temperature, a.amplitude, a.frequency)
    pid = results["pid"]["points"]["error_rms_um"][0]
    print(f"{a.amplitude:g} um at {a.frequency:g} Hz, {a.temperature:g} degC; errors over the last period")
    print(f"  {'controller':40s} {'RMS um':>9s} {'peak um':>9s} {'RMS / PID':>10s}")
    for name, r in results.items():
        p = r["points"]
        print(f"  {LABELS[name]:40s} {p['error_rms_um'][0]:9.4f} {p['error_peak_um'][0]:9.4f} "
              f"{p['error_rms_um'][0] / pid:10.3f}")
    fig = figure(results, a.temperature, a.amplitude, a.frequency)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    for f in plots.save(fig, out, "compare_controllers"):
        print(f"  wrote {f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
