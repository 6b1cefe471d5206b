#!/usr/bin/python3
"""No header includes one of a higher layer (issue 38, item 4; docs/layers.md).

Every header of include/gmasim/ and src/ gets the rank of its layer (the table below, by
folder, or by file where a folder holds two layers); an `#include "gmasim/..."` or a
src-relative include of a higher rank is reported with the file, the line and both layers.
The root's forwarding headers (gmasim/model.hpp -> gmasim/model/model.hpp, kept for code
written against the flat layout) are exempt: they include what they forward to. Exit 0 if
clean, 1 with the list otherwise. Standard library only.
"""
from __future__ import annotations

import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent

# The layer order (docs/layers.md): physics -> model (with the magnetisation-law seam and the
# circuit) -> mechanics analysis (modes, linearisation: they take a Model) -> simulate ->
# experiments -> io -> identify -> capi.
LAYERS = ["root", "physics", "law_id", "model", "mechanics", "simulate", "experiments", "io",
          "identify", "capi"]
PUBLIC = {  # include/gmasim/<folder>/ -> layer
    "physics": "physics", "magnetisation": "model", "model": "model", "mechanics": "mechanics",
    "simulate": "simulate", "experiments": "experiments", "io": "io", "identify": "identify",
    "capi": "capi",
}
PUBLIC_FILES = {"magnetisation/law_id.hpp": "law_id", "errors.hpp": "root", "version.h": "root"}
PRIVATE = {  # src/<folder>/ -> layer
    "common": "root", "circuit": "model", "model": "model", "thermal": "model",
    "mechanics": "mechanics", "simulate": "simulate", "lanes": "simulate",
    "experiments": "experiments", "io": "io", "identify": "identify", "capi": "capi",
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of_public(rel: str) -> str | None:
    """The layer of include/gmasim/<rel>; None for a root forwarding header."""
    if rel in PUBLIC_FILES:
        return PUBLIC_FILES[rel]
    folder = rel.split("/")[0]
    if "/" not in rel:
        return None  # a root forwarding header
    return PUBLIC.get(folder)


def layer_of_include(inc: str, includer: pathlib.Path) -> str | None:
    if inc.startswith("gmasim/"):
        return layer_of_public(inc[len("gmasim/"):])
    src = ROOT / "src"
    for base in (includer.parent, src):
        p = (base / inc).resolve()
        if p.is_file() and src in p.parents:
            return PRIVATE.get(p.relative_to(src).parts[0])
    return None


def headers():
    inc = ROOT / "include" / "gmasim"
    for p in sorted(inc.rglob("*")):
        if p.suffix in (".hpp", ".h") and p.is_file():
            yield p, layer_of_public(str(p.relative_to(inc)))
    src = ROOT / "src"
    for p in sorted(src.rglob("*")):
        if p.suffix in (".hpp", ".h") and p.is_file():
            yield p, PRIVATE.get(p.relative_to(src).parts[0])


def main(argv=None) -> int:
    global ROOT
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", default=str(ROOT), help="the source tree (default: this repository)")
    ROOT = pathlib.Path(ap.parse_args(argv).root).resolve()
    problems = []
    checked = 0
    for path, layer in headers():
        if layer is None:
            continue
        checked += 1
        for n, line in enumerate(path.read_text().splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            target = layer_of_include(m.group(1), path)
            if target is not None and LAYERS.index(target) > LAYERS.index(layer):
                problems.append(f"{path.relative_to(ROOT)}:{n}: a {layer} header includes "
                                f"\"{m.group(1)}\", of the higher layer {target}")
    for p in problems:
        print(p)
    print(f"check_header_layers: {checked} headers, {len(problems)} upward include(s) "
          f"(order: {' < '.join(LAYERS)})")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
