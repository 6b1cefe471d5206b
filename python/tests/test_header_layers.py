"""scripts/check_header_layers.py (issue 38, item 4): no header includes one of a higher layer."""
import importlib.util
import pathlib

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("check_header_layers",
                                               SOURCE_DIR / "scripts" / "check_header_layers.py")
layers = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(layers)


def test_the_repository_has_no_upward_include(capsys):
    assert layers.main(["--root", str(SOURCE_DIR)]) == 0
    assert "0 upward include(s)" in capsys.readouterr().out


def _tree(tmp_path, files):
    for rel, text in files.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return tmp_path


def test_an_upward_include_is_reported_with_file_line_and_layers(tmp_path, capsys):
    # The two kinds issue 38 found: a physics header including the mechanics analysis, and a
    # private src header reaching into a higher layer's private header.
    root = _tree(tmp_path, {
        "include/gmasim/physics/mechanics.hpp": '#pragma once\n#include "gmasim/mechanics/oscillator.hpp"\n',
        "include/gmasim/mechanics/oscillator.hpp": '#pragma once\n#include "gmasim/model/model.hpp"\n',
        "include/gmasim/model/model.hpp": '#pragma once\n#include "gmasim/errors.hpp"\n',
        "include/gmasim/errors.hpp": "#pragma once\n",
        "include/gmasim/model.hpp": '#include "gmasim/model/model.hpp"\n',  # a forwarder: exempt
        "src/lanes/kernel.h": '#include "experiments/plan.hpp"\n',
        "src/experiments/plan.hpp": '#include "gmasim/model/model.hpp"\n',
    })
    assert layers.main(["--root", str(root)]) == 1
    out = capsys.readouterr().out
    assert ('include/gmasim/physics/mechanics.hpp:2: a physics header includes '
            '"gmasim/mechanics/oscillator.hpp", of the higher layer mechanics') in out
    assert ('src/lanes/kernel.h:1: a simulate header includes "experiments/plan.hpp", of the '
            'higher layer experiments') in out
    assert "2 upward include(s)" in out  # mechanics -> model and experiments -> model are downward


def test_the_law_is_dispatched_in_one_place():
    """Issue 38, item 2: `with_magnetisation_law` (gmasim/magnetisation/laws.hpp) is the one
    place that turns the model's law into code; no other file of the library, the CLI, the
    Python module or the benchmarks compares the option with a law. The lanes' structure flag (src/lanes/pack.cpp, `st.preisach`) is the one left, until the lanes take
    their law from the same seam."""
    import re
    allowed = {"src/lanes/pack.cpp": 1}
    found = {}
    for folder in ("src", "include", "apps", "python/src", "bench"):
        for p in (SOURCE_DIR / folder).rglob("*"):
            if p.suffix not in (".cpp", ".hpp", ".h") or not p.is_file():
                continue
            n = len(re.findall(r"magnetisation_law\s*[!=]=\s*MagnetisationLaw::", p.read_text()))
            if n:
                found[str(p.relative_to(SOURCE_DIR))] = n
    assert found == allowed
