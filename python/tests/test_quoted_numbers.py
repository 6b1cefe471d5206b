"""scripts/check_quoted_numbers.py: the marker syntax, the JSON locator, the default tolerance,
and that a wrong, unquoted or unreproducible number fails."""
import importlib.util
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

SCRIPT = SOURCE_DIR / "scripts" / "check_quoted_numbers.py"
spec = importlib.util.spec_from_file_location("check_quoted_numbers", SCRIPT)
cq = importlib.util.module_from_spec(spec)
sys.modules["check_quoted_numbers"] = cq  # dataclasses look the module up
spec.loader.exec_module(cq)

CMD = ("gmasim sensitivity --param thermal_expansion.sleeve_length_m --claim thermal_model "
       "--json -")
PTR = "/entries/thermal_model/thermal_expansion.sleeve_length_m/derivative"


def test_default_tolerance_is_half_the_last_digit():
    assert cq.default_tolerance("2.53") == pytest.approx(0.005)
    assert cq.default_tolerance("-12") == pytest.approx(0.5)
    assert cq.default_tolerance("1.5e-3") == pytest.approx(5e-5)


def test_pointer_and_selection():
    doc = {"rows": [{"id": "a", "v": 1}, {"id": "b", "v": 2}], "a/b": {"x~y": 3}}
    assert cq.resolve_pointer(doc, "/rows/[id=b]/v") == 2
    assert cq.resolve_pointer(doc, "/rows/0/v") == 1
    assert cq.resolve_pointer(doc, "/a~1b/x~0y") == 3
    with pytest.raises(KeyError, match="no element with id = c"):
        cq.resolve_pointer(doc, "/rows/[id=c]/v")


def test_quote_must_be_a_whole_number_of_the_text():
    assert cq.quoted_in("lowers it by **0.41 pp**", "-0.41")
    assert not cq.quoted_in("the value 10.415", "0.41")
    assert not cq.quoted_in("the value 0.415", "0.41")


def test_markers_in_code_are_examples(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("Use `<!-- check: gmasim x | /a ~= 1 -->` like this.\n\n```\n"
                    "<!-- check: gmasim y | /b ~= 2 -->\n```\n\nIt is 3.\n"
                    "<!-- check: gmasim z | /c ~= 3 -->\n")
    checks = cq.parse_file(page)
    assert [c.command for c in checks] == [["gmasim", "z"]]
    assert checks[0].line == 8


def test_marker_syntax_errors(tmp_path):
    with pytest.raises(cq.MarkerError, match="must start with 'gmasim'"):
        cq.parse_marker("rm -rf / | /x ~= 1", tmp_path, 1, "1")
    with pytest.raises(cq.MarkerError, match="is not 'LOCATOR ~= VALUE"):
        cq.parse_marker("gmasim thermal | /x is 1", tmp_path, 1, "1")
    c = cq.parse_marker("gmasim  thermal --out {tmp}/t |  {tmp}/t/thermal.json#/meta/x ≈ 2.5 ± 1%",
                        tmp_path, 3, "2.5")
    assert c.command == ["gmasim", "thermal", "--out", "{tmp}/t"]
    assert c.file_part == "{tmp}/t/thermal.json" and c.pointer == "/meta/x"
    assert c.tolerance == pytest.approx(0.025)


def run(gmasim_bin, tmp_path, text):
    page = tmp_path / "page.md"
    page.write_text(text)
    return subprocess.run([sys.executable, str(SCRIPT), "--gmasim", gmasim_bin, "--root",
                           str(SOURCE_DIR), "--require-checks", str(page)],
                          capture_output=True, text=True, timeout=300)


def test_holds_and_fails(gmasim_bin, tmp_path):
    good = run(gmasim_bin, tmp_path, f"It is -17.2 um/degC/m.\n<!-- check: {CMD} | {PTR} ~= -17.2 -->\n")
    assert good.returncode == 0, good.stdout + good.stderr
    assert "1 of 1 quoted numbers hold" in good.stdout
    wrong = run(gmasim_bin, tmp_path, f"It is -17.3 um/degC/m.\n<!-- check: {CMD} | {PTR} ~= -17.3 -->\n")
    assert wrong.returncode == 1
    assert "page.md:2: FAIL" in wrong.stdout and "= -17.2, quoted -17.3" in wrong.stdout
    unquoted = run(gmasim_bin, tmp_path, f"It is negative.\n<!-- check: {CMD} | {PTR} ~= -17.2 -->\n")
    assert unquoted.returncode == 1 and "does not show the quoted number" in unquoted.stdout
    broken = run(gmasim_bin, tmp_path, "It is 1.\n<!-- check: gmasim sensitivity --nope | /x ~= 1 -->\n")
    assert broken.returncode == 1 and "failed: exit status 1" in broken.stdout
    empty = run(gmasim_bin, tmp_path, "No marker here.\n")
    assert empty.returncode == 1 and "no check marker" in empty.stdout
    bad = run(gmasim_bin, tmp_path, "<!-- check: python -c 1 | /x ~= 1 -->\n")
    assert bad.returncode == 2
