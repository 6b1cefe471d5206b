"""The automated figure check (gmasim.figure_check): what it finds on figures built to have one
defect each, and that every figure the tool writes passes it (issue 20).

The second part runs each command at a small size (data only), then draws its figures in this
process through gmasim.plots.save with a hook that collects the check's findings before
anything is written: a title, axis labels with units, no two visible texts overlapping (by
matplotlib's own extents) and no legend over a line.
"""
import os
import pathlib
import subprocess
import time

import numpy as np
import pytest

from gmasim import command_figures, figure_check, plots, report_figures
from gmasim.plots import plt


# ---- the check itself --------------------------------------------------------------------

def _clean():
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot([0, 1, 2], [0, 1, 4], label="y")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("displacement (µm)")
    ax.set_title("a clean figure")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.tight_layout()
    return fig


def test_a_clean_figure_has_no_problems():
    assert figure_check.problems(_clean()) == []


def test_missing_title_and_units_are_found():
    fig = _clean()
    ax = fig.axes[0]
    ax.set_title("")
    ax.set_ylabel("displacement")
    found = figure_check.problems(fig)
    assert "no title" in found
    assert any("y label 'displacement' has no unit" in p for p in found), found


def test_overlapping_texts_are_found_by_their_extents():
    fig = _clean()
    ax = fig.axes[0]
    ax.text(1.0, 2.0, "resonance 1272 Hz", fontsize=9)
    ax.text(1.02, 2.05, "resonance 1290 Hz", fontsize=9)  # the 20 and 70 degC labels of issue 20
    ax.text(0.1, 3.5, "alone", fontsize=9)
    found = figure_check.problems(fig)
    assert len(found) == 1 and "resonance 1272 Hz" in found[0] and "resonance 1290 Hz" in found[0], found


def test_crowded_tick_labels_are_found():
    fig, ax = plt.subplots(figsize=(3, 2.5))
    ax.plot([100000, 160000], [0, 1])
    ax.set_xticks(np.arange(100000, 160001, 10000))  # "1000001100001200001300000..." (issue 20)
    ax.tick_params(labelsize=10)
    ax.set_xlabel("field H (A/m)")
    ax.set_ylabel("strain (ppm)")
    ax.set_title("ticks")
    found = figure_check.problems(fig)
    assert any("x tick" in p and "overlaps x tick" in p for p in found), found


def test_a_legend_over_a_line_is_found():
    fig, ax = plt.subplots(figsize=(5, 3.5))
    x = np.linspace(0, 1, 50)
    ax.plot(x, np.ones_like(x), label="flat line at the top")
    ax.plot(x, np.zeros_like(x), label="bottom")
    ax.set_ylim(-0.1, 1.05)
    ax.legend(loc="upper right")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("y (µm)")
    ax.set_title("legend")
    found = figure_check.problems(fig)
    assert any("covers 'flat line at the top'" in p for p in found), found


def test_save_runs_the_hook_before_writing(tmp_path, monkeypatch):
    seen = []
    hook = plots.add_save_hook(lambda fig, stem: seen.append((stem, figure_check.problems(fig))))
    try:
        plots.save(_clean(), tmp_path, "clean")
    finally:
        plots.remove_save_hook(hook)
    assert seen == [("clean", [])]
    monkeypatch.setenv("GMASIM_FIGURE_CHECK", "1")
    fig = _clean()
    fig.axes[0].set_title("")
    with pytest.raises(figure_check.FigureProblem, match="no title"):
        plots.save(fig, tmp_path, "untitled")
    assert not (tmp_path / "untitled.png").exists()


# ---- every figure the tool writes ---------------------------------------------------------

def _run(gmasim_bin, *args):
    r = subprocess.run([gmasim_bin, *map(str, args)], capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, f"{' '.join(map(str, args))}:\n{r.stdout}\n{r.stderr}"
    return r


# Each command at a small size; (command, directory, arguments).
COMMANDS = [
    ("simulate", "simulate", ["simulate", "--periods", "2", "--temperature", "70"]),
    ("simulate", "simulate_heat", ["simulate", "--periods", "20", "--frequency", "50", "--self-heating"]),
    ("frf", "frf_small", ["frf", "--method", "linear", "--points", "12"]),
    ("frf", "frf_large", ["frf", "--amplitude", "1", "--points", "5", "--f-min", "950", "--f-max", "1900",
                          "--peak-refinements", "4", "--temperatures", "20,70"]),
    ("sweep", "sweep", ["sweep", "--temperatures", "20,70", "--currents", "6,8", "--frequencies", "10",
                        "--periods", "2"]),
    ("track", "track", ["track", "--temperatures", "20,70", "--amplitudes", "10", "--frequencies", "100",
                        "--periods", "2"]),
    ("compensate", "compensate", ["compensate", "--temperatures", "20,70", "--track-temperatures", "20,70",
                                  "--track-amplitudes", "10", "--track-frequencies", "100"]),
    ("ablate", "ablate", ["ablate", "--frequencies", "10", "--periods", "2"]),
    ("params", "params", ["params-vs-temperature", "--temperatures", "20,70,150", "--periods", "2"]),
    ("track_feedforward", "track_ff", ["track", "--feedforward", "inverse", "--mismatch", "none",
                                       "--temperatures", "20,70", "--amplitudes", "10",
                                       "--frequencies", "10,100", "--periods", "2"]),
    ("sensitivity", "sensitivity", ["sensitivity", "--param", "material.Ms_A_per_m", "--param",
                                    "material.chi_m", "--claim", "stroke_drop_8A", "--claim",
                                    "hysteresis_drop_8A"]),
    ("design", "design", ["design", "--variable", "preload.force_N=950:3000", "--variable",
                          "drive.current_pp_A=4:12", "--maximize", "stroke_um@20", "--minimize",
                          "coil_copper_loss_W@20", "--constraint", "temperature_rise_K@20<=20",
                          "--population", "8", "--generations", "2"]),
]


@pytest.fixture(scope="module")
def figure_problems(gmasim_bin, tmp_path_factory, reproduce_quick):
    """{stem: problems} of every figure the commands' renderers and the reproduce report
    draw, collected by a save hook, and the time the whole run took."""
    root = tmp_path_factory.mktemp("figures")
    t0 = time.monotonic()
    found = {}

    def hook(fig, stem):
        found[f"{current[0]}/{stem}"] = figure_check.problems(fig)

    current = [""]
    hook = plots.add_save_hook(hook)
    try:
        for command, name, args in COMMANDS:
            out = root / name
            _run(gmasim_bin, *args, "--out", out)
            current[0] = name
            command_figures.render(command, out)
        ident = root / "identify"
        _run(gmasim_bin, "identify", "synthesize", "--out", ident / "data", "--temperatures", "20",
             "--currents", "8", "--frequencies", "10", "--periods", "2", "--samples-per-period", "60")
        _run(gmasim_bin, "identify", "--data", ident / "data" / "manifest.toml", "--fit",
             pathlib.Path(os.environ.get("GMASIM_SOURCE_DIR", ".")) / "examples" / "identify_synthetic" / "fit.toml",
             "--out", ident / "fitted.toml", "--report", ident / "report", "--islands", "1", "--population", "8",
             "--generations", "2", "--no-refine", "--no-profile", "--no-plots")
        current[0] = "identify"
        command_figures.render("identify", ident / "report")
        current[0] = "reproduce"  # the report's figures, drawn again from its data
        report_figures.render(reproduce_quick)
    finally:
        plots.remove_save_hook(hook)
    return found, time.monotonic() - t0


def test_every_figure_the_tool_writes_reads_alone(figure_problems):
    found, _seconds = figure_problems
    expected = {"simulate/simulate", "simulate_heat/simulate", "simulate_heat/self_heating", "frf_small/frf",
                "frf_large/frf", "sweep/sweep", "track/track", "compensate/compensate", "ablate/ablate",
                "params/params", "track_ff/track_feedforward", "sensitivity/sensitivity", "design/design",
                "identify/convergence", "reproduce/claims", "reproduce/loops_8A_10Hz",
                "reproduce/sweep_10Hz", "reproduce/frf", "reproduce/track", "reproduce/retention",
                "reproduce/params_vs_temperature", "reproduce/ablate"}
    assert expected <= set(found), sorted(expected - set(found))
    assert any(k.startswith("identify/overlay_") for k in found), sorted(found)
    bad = {k: v for k, v in found.items() if v}
    assert not bad, "\n".join(f"{k}: {p}" for k, v in bad.items() for p in v)


def test_the_large_signal_frf_figure_says_so(gmasim_bin, tmp_path):
    out = tmp_path / "frf"
    r = _run(gmasim_bin, "frf", "--amplitude", "1", "--points", "5", "--f-min", "950", "--f-max", "1900",
             "--temperatures", "20", "--peak-refinements", "6", "--out", out)
    assert "large signal" in r.stdout
    assert "warning" in r.stderr and "large" in r.stderr
    summ = plots.read_csv(out / "frf_summary.csv")
    assert summ["large_signal"][0] == "true" and summ["markers_from"][0] == "stepped sine"
    fig = command_figures.bode_db(out)
    assert "large signal" in fig.axes[0].get_title()
    frf = plots.read_csv(out / "frf.csv")
    # the -3 dB reference is the plotted stepped sine's gain at the lowest frequency
    assert summ["reference_gain_um_per_A"][0] == pytest.approx(frf["stepped_mag_um_per_A"][0], rel=1e-9)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]  # one legend under both panels
    assert any("1270 Hz" in t for t in labels), labels
    assert fig.axes[0].get_ylabel() == "|Y/I| (µm/A)" and fig.axes[0].get_yscale() == "log"
    # the grid, the stepped point at the linearisation's peak and the refinement's 6 evaluations
    assert len(frf["frequency_Hz"]) == 5 + 1 + 6  # observed 12
    assert np.all(np.diff(frf["frequency_Hz"]) > 0)
    plt.close(fig)


def test_power_of_ten_tick_labels_are_found_and_plain_log_axes_pass():
    """Issue 41: convergence.png and the FRF labelled ticks '2x10^0', '6x10^0'."""
    import matplotlib.pyplot as plt

    from gmasim import plots
    fig, ax = plt.subplots()
    ax.semilogy([0, 1, 2], [1.5, 3.0, 8.0], label="e")
    ax.set_title("t")
    ax.set_xlabel("x (s)")
    ax.set_ylabel("y (µm)")
    found = figure_check.problems(fig)
    assert any("a power of ten to write as a plain number" in p for p in found), found
    plots.plain_log_axis(ax, "y")
    assert not [p for p in figure_check.problems(fig) if "power of ten" in p]
    plt.close(fig)
