"""The loops of ``gmasim simulate --temperature 20,150 --plot`` overlaid: one curve per
temperature, each from the output set the command wrote for it.

    /usr/bin/python3 -m gmasim.simulate_overlay OUT_DIR RUN_DIR...

writes OUT_DIR/simulate_temperatures.png and .svg (:func:`gmasim.plots.save`): displacement
against current over each run's metrics window (the last period of a periodic run), labelled
with its temperature, stroke and thermal offset drift (metrics.json).
"""
from __future__ import annotations

import json
import pathlib
import sys

from gmasim import plots
from gmasim.plots import plt, read_csv


def overlay(out, runs):
    fig = plt.figure(figsize=(7, 5))
    ax = fig.add_subplot(1, 1, 1)
    for run in runs:
        run = pathlib.Path(run)
        ts = read_csv(run / "timeseries.csv")
        meta = json.loads((run / "metrics.json").read_text())
        m = meta.get("metrics") or {}
        keep = ts["t_s"] >= m.get("window_start_s", 0.0)
        label = (f"{meta['temperature_C']:g} °C: stroke {m.get('stroke_um', 0):.1f} µm, "
                 f"thermal drift {meta['thermal_expansion_um']:.1f} µm")
        ax.plot(ts["current_A"][keep], ts["y_um"][keep], lw=1.0, label=label)
    ax.set_xlabel("current (A)")
    ax.set_ylabel("displacement y (µm)")
    ax.set_title("y against current at each temperature (last period)")
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    return plots.save(fig, out, "simulate_temperatures")


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) < 2:
        print("usage: python3 -m gmasim.simulate_overlay OUT_DIR RUN_DIR...", file=sys.stderr)
        return 1
    try:
        overlay(argv[0], argv[1:])
    except (OSError, KeyError, ValueError) as e:
        print(f"gmasim.simulate_overlay: {argv[0]}: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
