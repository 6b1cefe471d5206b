"""Render the figures of a `gmasim reproduce` output directory from its CSV data.

    /usr/bin/python3 -m gmasim.report_figures OUT_DIR

Reads OUT_DIR/data/*.csv (and OUT_DIR/claims.json: the paper's numbers are marked beside
ours, coloured by whether the claim passes) and writes OUT_DIR/figures/<name>.png and .svg.
"""
from __future__ import annotations

import pathlib
import sys

from . import plots


def render(out_dir) -> list[pathlib.Path]:
    out = pathlib.Path(out_dir)
    data, figs = out / "data", out / "figures"
    written = []

    def have(name):
        return (data / name).exists()

    claims = plots.read_claims(out / "claims.json") if (out / "claims.json").exists() else None
    if claims:
        written += plots.save(plots.claims_overview(claims), figs, "claims")

    if have("loops_8A_10Hz.csv"):
        written += plots.save(plots.hysteresis_loops(plots.read_csv(data / "loops_8A_10Hz.csv"),
                                                     title="Hysteresis loops at 8 A, 10 Hz, coloured by temperature"),
                              figs, "loops_8A_10Hz")
    if have("sweep_10Hz.csv"):
        written += plots.save(plots.sweep_vs_temperature(plots.read_csv(data / "sweep_10Hz.csv"), 10.0, claims=claims), figs,
                              "sweep_10Hz")
    if have("frf.csv"):
        written += plots.save(plots.bode(plots.read_csv(data / "frf.csv"), claims=claims), figs, "frf")
    if have("track.csv"):
        written += plots.save(plots.tracking_error(plots.read_csv(data / "track.csv"), claims=claims), figs, "track")
    if have("params_retention.csv"):
        written += plots.save(plots.retention(plots.read_csv(data / "params_retention.csv"), claims=claims), figs, "retention")
    if have("params.csv"):
        written += plots.save(plots.params_vs_temperature(plots.read_csv(data / "params.csv"), claims=claims), figs,
                              "params_vs_temperature")
    if have("ablate.csv"):
        written += plots.save(plots.ablation(plots.read_csv(data / "ablate.csv")), figs, "ablate")
    return written


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print("usage: python3 -m gmasim.report_figures OUT_DIR", file=sys.stderr)
        return 2
    files = render(argv[0])
    print(f"gmasim.report_figures: wrote {len(files)} files to {pathlib.Path(argv[0]) / 'figures'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
