#!/usr/bin/env python3
"""Reruns the commands a markdown page quotes and checks the numbers it quotes from them.

A quoted number is marked by an HTML comment (invisible in the rendered page) in the
paragraph that shows the number:

    Raising M_s by 1 % lowers the 8 A stroke drop by **0.063 pp**.
    <!-- check: gmasim sensitivity --param material.Ms_A_per_m --claim stroke_drop_8A --json -
         | /entries/stroke_drop_8A/material.Ms_A_per_m/derivative ~= -6.35 +- 0.05 -->

    <!-- check: COMMAND | LOCATOR ~= VALUE [+- TOLERANCE] -->

COMMAND      a gmasim command line (split like a POSIX shell, never run by one): its first word
             must be `gmasim`, replaced by --gmasim; `{tmp}` anywhere stands for a fresh
             temporary directory of this check. It runs in --root (default: the repository
             the page is in), so paths such as calibration/consistent.toml work as typed.
LOCATOR      `/json/pointer` into the command's standard output (a JSON document: give the
             command `--json -`), or `FILE#/json/pointer` into a JSON file it wrote (FILE
             relative to --root, or under {tmp}). The pointer is RFC 6901 (~0 for ~, ~1 for
             /), plus one extension: a segment `[key=value]` selects the first element of an
             array whose member `key` equals value (`/tables/claims/rows/[id=flux_drop_6A]/ours`).
VALUE        the number as the paragraph shows it; it (or the same digits without the sign, for
             "lowers by 0.41") must appear in the paragraph's visible text, so the text and the
             check cannot drift apart.
TOLERANCE    `+- 0.05` (absolute) or `+- 2%` (relative to VALUE); default: half a unit in the
             last digit of VALUE (the quote is the result rounded as written).
`~=` may also be written `≈` or `==`, `+-` also `±`. The comment may span lines. A marker
inside a code block or an inline code span is an example, not a check.

Each distinct command runs once per invocation. Exit status: 0 every check holds, 1 a check
failed (each failure printed as file:line: what, the number found and the one quoted), 2 a
malformed marker or bad usage.

    /usr/bin/python3 scripts/check_quoted_numbers.py --gmasim build/ci/bin/gmasim docs/failing_claims.md
"""
from __future__ import annotations

import argparse
import concurrent.futures
import dataclasses
import json
import math
import pathlib
import re
import shlex
import subprocess
import sys
import tempfile

MARKER = re.compile(r"<!--\s*check:(.*?)-->", re.S)
COMMENT = re.compile(r"<!--.*?-->", re.S)
# LOCATOR (~=|≈|==) VALUE [(+-|±) TOL[%]]
RHS = re.compile(r"^\s*(?P<loc>\S+)\s*(?:~=|≈|==)\s*(?P<value>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
                 r"\s*(?:(?:\+-|±)\s*(?P<tol>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(?P<pct>%)?)?\s*$")


class MarkerError(Exception):
    """A malformed check comment (exit status 2)."""


@dataclasses.dataclass
class Check:
    file: pathlib.Path
    line: int
    command: list[str]
    file_part: str | None  # FILE of FILE#/pointer, None for standard output
    pointer: str
    value_text: str
    tolerance: float
    paragraph: str  # the visible text of the paragraph holding the marker

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}"


def default_tolerance(value_text: str) -> float:
    """Half a unit in the last digit written: "2.53" -> 0.005, "12" -> 0.5, "1.5e-3" -> 5e-5."""
    mant, _, exp = value_text.lower().partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 0.5 * 10.0 ** (-decimals) * 10.0 ** (int(exp) if exp else 0)


def paragraph_at(text: str, pos: int) -> str:
    """The visible text (comments removed) of the blank-line-separated block around pos."""
    start = text.rfind("\n\n", 0, pos)
    end = text.find("\n\n", pos)
    block = text[start + 2 if start >= 0 else 0: end if end >= 0 else len(text)]
    return COMMENT.sub(" ", block)


def parse_marker(body: str, file: pathlib.Path, line: int, paragraph: str) -> Check:
    body = " ".join(body.split())
    if " | " not in body:
        raise MarkerError(f"{file}:{line}: check without ' | ' between the command and the locator")
    cmd_text, rhs = body.rsplit(" | ", 1)
    try:
        command = shlex.split(cmd_text)
    except ValueError as e:
        raise MarkerError(f"{file}:{line}: the command does not split: {e}") from None
    if not command or command[0] != "gmasim":
        raise MarkerError(f"{file}:{line}: a quoted command must start with 'gmasim' "
                          f"(got {cmd_text[:60]!r})")
    m = RHS.match(rhs)
    if not m:
        raise MarkerError(f"{file}:{line}: '{rhs}' is not 'LOCATOR ~= VALUE [+- TOLERANCE[%]]'")
    loc = m["loc"]
    file_part, sep, pointer = loc.partition("#")
    if not sep:
        file_part, pointer = None, loc
    if not pointer.startswith("/"):
        raise MarkerError(f"{file}:{line}: the JSON pointer '{pointer}' must start with '/'")
    value_text = m["value"]
    if m["tol"] is None:
        tol = default_tolerance(value_text)
    else:
        tol = float(m["tol"]) * (abs(float(value_text)) / 100.0 if m["pct"] else 1.0)
    return Check(file, line, command, file_part, pointer, value_text, tol, paragraph)


FENCE = re.compile(r"^(```|~~~).*?^\1[^\n]*$", re.S | re.M)
CODE_SPAN = re.compile(r"(`+)(?!`).*?(?<!`)\1(?!`)", re.S)


def without_code(text: str) -> str:
    """The text with fenced code blocks and inline code spans blanked (newlines kept): a
    marker shown as an example in code is not a check."""
    blank = lambda m: re.sub(r"[^\n]", " ", m.group(0))  # noqa: E731
    return CODE_SPAN.sub(blank, FENCE.sub(blank, text))


def parse_file(path: pathlib.Path) -> list[Check]:
    text = path.read_text(encoding="utf-8")
    checks = []
    for m in MARKER.finditer(without_code(text)):
        line = text.count("\n", 0, m.start()) + 1
        checks.append(parse_marker(m.group(1), path, line, paragraph_at(text, m.start())))
    return checks


def resolve_pointer(doc, pointer: str):
    """RFC 6901 plus `[key=value]` array selection; raises KeyError naming the missing step."""
    node = doc
    for raw in pointer.split("/")[1:]:
        seg = raw.replace("~1", "/").replace("~0", "~")
        if isinstance(node, list):
            sel = re.fullmatch(r"\[([^=\]]+)=([^\]]*)\]", seg)
            if sel:
                key, want = sel.groups()
                found = [x for x in node if isinstance(x, dict) and _matches(x.get(key), want)]
                if not found:
                    raise KeyError(f"no element with {key} = {want}")
                node = found[0]
            elif seg.isdigit() and int(seg) < len(node):
                node = node[int(seg)]
            else:
                raise KeyError(f"'{seg}' is not an index of an array of {len(node)}")
        elif isinstance(node, dict):
            if seg not in node:
                raise KeyError(f"no member '{seg}'")
            node = node[seg]
        else:
            raise KeyError(f"'{seg}': {type(node).__name__} has no members")
    return node


def _matches(have, want: str) -> bool:
    if isinstance(have, (int, float)) and not isinstance(have, bool):
        try:
            return float(want) == float(have)
        except ValueError:
            return False
    return str(have) == want


def quoted_in(paragraph: str, value_text: str) -> bool:
    unsigned = value_text.lstrip("+-")
    # Not part of a longer number: "0.41" must not match inside "10.415".
    pat = r"(?<![\d.])[-+−]?" + re.escape(unsigned) + r"(?![\d])"
    return re.search(pat, paragraph) is not None


class Runner:
    """Runs each distinct command once, whichever file quotes it; {tmp} is one directory per
    command. prefetch() runs the distinct commands `jobs` at a time (each is one process with
    its own {tmp}, so they do not share state); run() then reads the cache."""

    def __init__(self, gmasim: str, root: pathlib.Path, timeout: float):
        self.gmasim, self.root, self.timeout = gmasim, root, timeout
        self.cache: dict[tuple, tuple[str, pathlib.Path | None, str]] = {}
        self.tmp = tempfile.TemporaryDirectory(prefix="gmasim_check_")

    def prefetch(self, checks: list[Check], jobs: int) -> None:
        keys = list(dict.fromkeys(tuple(c.command) for c in checks))
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            list(pool.map(self._execute, keys))

    def _execute(self, key: tuple) -> None:
        if key in self.cache:
            return
        tmp = pathlib.Path(tempfile.mkdtemp(dir=self.tmp.name))
        argv = [self.gmasim] + [a.replace("{tmp}", str(tmp)) for a in key[1:]]
        try:
            p = subprocess.run(argv, cwd=self.root, capture_output=True, text=True,
                               timeout=self.timeout)
        except subprocess.TimeoutExpired:
            self.cache[key] = ("", tmp, f"timed out after {self.timeout:g} s")
        else:
            err = "" if p.returncode == 0 else (
                f"exit status {p.returncode}: {p.stderr.strip()[-400:]}")
            self.cache[key] = (p.stdout, tmp, err)

    def run(self, check: Check) -> tuple[str, pathlib.Path]:
        key = tuple(check.command)
        self._execute(key)
        stdout, tmp, err = self.cache[key]
        if err:
            raise RuntimeError(f"`{' '.join(check.command)}` failed: {err}")
        return stdout, tmp


def evaluate(check: Check, runner: Runner) -> tuple[bool, str]:
    if not quoted_in(check.paragraph, check.value_text):
        return False, (f"the paragraph does not show the quoted number {check.value_text} "
                       "(the check must sit in the paragraph that quotes it)")
    try:
        stdout, tmp = runner.run(check)
        if check.file_part is None:
            doc = json.loads(stdout)
        else:
            path = pathlib.Path(check.file_part.replace("{tmp}", str(tmp)))
            doc = json.loads((path if path.is_absolute() else runner.root / path).read_text())
        got = resolve_pointer(doc, check.pointer)
    except (RuntimeError, KeyError, OSError, json.JSONDecodeError) as e:
        return False, f"{check.pointer}: {e}"
    if not isinstance(got, (int, float)) or isinstance(got, bool) or not math.isfinite(got):
        return False, f"{check.pointer} is {got!r}, not a finite number"
    want = float(check.value_text)
    ok = abs(got - want) <= check.tolerance
    return ok, f"{check.pointer} = {got:.6g}, quoted {check.value_text} +- {check.tolerance:.3g}"


def markdown_files(paths: list[str]) -> list[pathlib.Path]:
    out = []
    for p in map(pathlib.Path, paths):
        out += sorted(p.glob("*.md")) if p.is_dir() else [p]
    return out


def find_root(path: pathlib.Path) -> pathlib.Path:
    for d in [path.resolve().parent, *path.resolve().parents]:
        if (d / ".git").exists() or (d / "CMakePresets.json").exists():
            return d
    return path.resolve().parent


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+", help="markdown files, or directories (their *.md)")
    ap.add_argument("--gmasim", required=True, help="the gmasim executable to run")
    ap.add_argument("--root", help="working directory of the commands (default: the repository)")
    ap.add_argument("--timeout", type=float, default=1800.0, help="per command [s]")
    ap.add_argument("--jobs", type=int, default=2,
                    help="distinct commands run at once (default 2: the CI machine's cores)")
    ap.add_argument("--require-checks", action="store_true",
                    help="fail if a file holds no check (a test page must test something)")
    a = ap.parse_args(argv)
    files = markdown_files(a.files)
    try:
        checks = {f: parse_file(f) for f in files}
    except (MarkerError, OSError, UnicodeDecodeError) as e:
        print(f"check_quoted_numbers: {e}", file=sys.stderr)
        return 2
    failed = empty = 0
    # One runner per working directory, so that a command quoted in several files runs once;
    # each runs its distinct commands `--jobs` at a time before the checks read them.
    roots = {f: pathlib.Path(a.root) if a.root else find_root(f) for f in files}
    by_root: dict[pathlib.Path, list[Check]] = {}
    for f, cs in checks.items():
        if cs:
            by_root.setdefault(roots[f], []).extend(cs)
    runners = {root: Runner(a.gmasim, root, a.timeout) for root in by_root}
    for root, cs in by_root.items():
        runners[root].prefetch(cs, a.jobs)
    for f, cs in checks.items():
        if not cs:
            if a.require_checks:
                print(f"{f}: FAIL: no check marker (<!-- check: ... -->)")
                empty += 1
            continue
        runner = runners[roots[f]]
        for c in cs:
            ok, what = evaluate(c, runner)
            print(f"{c.where}: {'ok' if ok else 'FAIL'}: {what}")
            failed += not ok
    total = sum(len(cs) for cs in checks.values())
    print(f"check_quoted_numbers: {total - failed} of {total} quoted numbers hold"
          f" ({len(files)} files)")
    return 1 if failed or empty else 0


if __name__ == "__main__":
    raise SystemExit(main())
