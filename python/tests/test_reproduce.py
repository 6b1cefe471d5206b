"""`gmasim reproduce` writes the report with every figure and the claims table."""
import csv


def test_reproduce_quick_writes_report_figures_and_claims(reproduce_quick):
    out = reproduce_quick
    report = (out / "report.md").read_text()
    for stem in ("claims", "loops_8A_10Hz", "sweep_10Hz", "frf", "track", "retention", "params_vs_temperature",
                 "ablate"):
        assert (out / "figures" / f"{stem}.png").stat().st_size > 5000, stem
        assert (out / "figures" / f"{stem}.svg").exists(), stem
        assert f"figures/{stem}.png" in report, stem
    rows = list(csv.DictReader(open(out / "claims.csv")))
    assert len(rows) >= 30
    assert {r["result"] for r in rows} <= {"pass", "fail", "n/a"}
    ids = {r["id"] for r in rows}
    assert {"stroke_drop_6A", "hysteresis_drop_12A", "flux_drop_8A", "first_resonance", "thermal_model"} <= ids
    # every applicable claim carries both numbers
    for r in rows:
        if r["result"] != "n/a" and r["id"] not in ("EG_largest", "ablation_rank_10Hz", "ablation_rank_200Hz"):
            assert r["paper"] and r["ours"], r["id"]
