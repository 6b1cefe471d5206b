#!/usr/bin/env python3
"""Size limits of the code base (issue 10): no source file over 600 lines, no function
over 80 lines, except the entries of scripts/code_size_allow.txt (each with its reason).

    /usr/bin/python3 scripts/code_size.py            # report; exit 1 if a limit is broken
    /usr/bin/python3 scripts/code_size.py --list 20  # also the 20 longest functions

A function is counted from the line of its opening brace to the line of its closing brace
(C++), or from its `def` line to its last non-blank line (Python); lambdas and local classes
count as part of the function that holds them. The C++ reader is a brace matcher over the
text with comments, strings and character literals blanked: a '{' opened in namespace,
class or `extern "C"` scope after a parameter list ')' starts a function.
"""
import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
CPP_DIRS = ["src", "include", "apps", "python/src", "tests", "bench", "fuzz"]
PY_DIRS = ["python/gmasim", "python/tests", "scripts", "calibration", "tests"]
CPP_EXT = {".cpp", ".hpp", ".h", ".cc"}
FILE_LIMIT = 600
FUNCTION_LIMIT = 80


def blank_cpp(text):
    """The text with comments, string and char literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not text[i - 1].isalnum()):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if m:
                end = text.find(")" + m.group(1) + '"', i)
                j = n if end < 0 else end + len(m.group(1)) + 2
                out.append(re.sub(r"[^\n]", " ", text[i:j]))
                i = j
            else:
                out.append(c)
                i += 1
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(" ")  # digit separator 1'000
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(" " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


CONTAINER = re.compile(r"\b(namespace|struct|class|union|enum)\b|extern\s*$")
CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|return)\b")


def cpp_functions(path):
    """[(name, first_line, last_line)] of the functions defined in a C++ file."""
    text = blank_cpp(path.read_text(encoding="utf-8", errors="replace"))
    stack = []  # per open brace: 'container', 'function', or 'other'
    head_start = 0  # where the text before the next '{' begins (after ; { or })
    line = 1
    open_line = []
    found = []
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c == "{":
            head = text[head_start:i]
            in_function = "function" in stack
            kind = "other"
            if not in_function:
                h = " ".join(head.split())
                if CONTAINER.search(h) and "(" not in h.split("=")[0][-1:] and not h.endswith(")"):
                    kind = "container"
                elif re.search(r"\)\s*(const|noexcept|override|final|mutable|->[^{]*|"
                               r":[^{]*|\s)*$", h) and not CONTROL.match(h) and "=" not in h.split("(")[0]:
                    kind = "function"
                elif h.startswith('extern "C"') or h == "extern":
                    kind = "container"
                else:
                    kind = "container" if CONTAINER.search(h) else "other"
            stack.append(kind)
            open_line.append((line, text[head_start:i]))
            head_start = i + 1
        elif c == "}":
            if stack:
                kind = stack.pop()
                start, head = open_line.pop()
                if kind == "function":
                    name = re.findall(r"([~\w:]+(?:operator\S*)?)\s*\(", head)
                    found.append((name[0] if name else "?", start, line))
            head_start = i + 1
        elif c == ";":
            head_start = i + 1
    return found


def py_functions(path):
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    found = []
    for k, l in enumerate(lines):
        m = re.match(r"^(\s*)(async\s+)?def\s+(\w+)", l)
        if not m:
            continue
        indent = len(m.group(1))
        if any(s for s in found if s[3] < indent and s[1] <= k + 1 <= s[2]):
            continue  # nested: counted with its outer function
        last = k
        for j in range(k + 1, len(lines)):
            s = lines[j]
            if not s.strip():
                continue
            if len(s) - len(s.lstrip()) <= indent and not s.lstrip().startswith((")", "]", "}")):
                break
            last = j
        found.append((m.group(3), k + 1, last + 1, indent))
    return [(n, a, b) for n, a, b, _ in found]


def files():
    for d in CPP_DIRS:
        for p in sorted((ROOT / d).rglob("*")):
            if p.suffix in CPP_EXT and "build" not in p.parts:
                yield p, cpp_functions
    seen = set()
    for d in PY_DIRS:
        for p in sorted((ROOT / d).rglob("*.py")):
            if p not in seen and "build" not in p.parts:
                seen.add(p)
                yield p, py_functions


def load_allow():
    allow = {}
    f = ROOT / "scripts" / "code_size_allow.txt"
    if f.exists():
        for raw in f.read_text().splitlines():
            s = raw.split("#", 1)[0].strip()
            if s:
                key = s.split()[0]
                allow[key] = raw.split("#", 1)[1].strip() if "#" in raw else ""
    return allow


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--list", type=int, default=0, help="also list the N longest functions")
    args = ap.parse_args()
    allow = load_allow()
    used = set()
    problems, functions = [], []
    for p, reader in files():
        rel = p.relative_to(ROOT).as_posix()
        n = len(p.read_text(encoding="utf-8", errors="replace").splitlines())
        if n > FILE_LIMIT:
            if rel in allow:
                used.add(rel)
            else:
                problems.append(f"{rel}: {n} lines (file limit {FILE_LIMIT})")
        for name, a, b in reader(p):
            length = b - a + 1
            functions.append((length, rel, name, a))
            key = f"{rel}:{name}"
            if length > FUNCTION_LIMIT:
                if key in allow:
                    used.add(key)
                else:
                    problems.append(f"{rel}:{a}: function {name}: {length} lines "
                                    f"(function limit {FUNCTION_LIMIT})")
    for k in sorted(set(allow) - used):
        problems.append(f"scripts/code_size_allow.txt: '{k}' is within the limits or gone; "
                        "remove the entry")
    if args.list:
        for length, rel, name, a in sorted(functions, reverse=True)[: args.list]:
            print(f"{length:5d}  {rel}:{a} {name}")
    for p in problems:
        print(p)
    print(f"code_size: {len(problems)} problem(s); {len(functions)} functions read")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
