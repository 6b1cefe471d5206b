"""Argument checks in front of the C++ functions (issue 19, item 11).

pybind11 reports a wrongly typed argument as "Unable to cast Python instance to C++ type", or
as "incompatible function arguments" with the whole signature, and a 0-d array where a list is
expected as "TypeError: len() of unsized object". ``checked(fn)`` wraps a function of the
extension module: before the call, every argument given is checked against the type its
signature (the first line of the pybind11 docstring) declares, and a mismatch is a TypeError
that names the function, the argument, the expected type and unit, and what was given:

    sweep(): temperatures_C must be a 1-D sequence of numbers [degC], not a 0-d numpy.ndarray
"""
from __future__ import annotations

import functools
import numbers

import numpy as np

_UNITS = [("_degC", "degC"), ("_C", "degC"), ("_Hz", "Hz"), ("_A", "A"), ("_s", "s"), ("_um", "um"),
          ("_pct", "%"), ("_T", "T"), ("_N", "N"), ("_m", "m")]


def _unit(name: str) -> str:
    for suffix, unit in _UNITS:
        if name.endswith(suffix):
            return f" [{unit}]"
    return ""


def _what(v) -> str:
    if isinstance(v, np.ndarray):
        return f"a {v.ndim}-d numpy.ndarray"
    return f"{type(v).__module__ + '.' if type(v).__module__ not in ('builtins',) else ''}{type(v).__name__} {v!r}"[:120]


def _is_number(v) -> bool:
    if isinstance(v, (bool, np.bool_, str, bytes)):
        return False
    if isinstance(v, numbers.Real):
        return True
    if isinstance(v, np.ndarray):
        return v.ndim == 0 and np.issubdtype(v.dtype, np.number)
    return False


def _is_integer(v) -> bool:
    return isinstance(v, (numbers.Integral, np.integer)) and not isinstance(v, (bool, np.bool_))


def _is_numbers_1d(v) -> bool:
    if isinstance(v, (str, bytes, dict)) or _is_number(v):
        return False
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        return False
    return a.ndim == 1


def _is_strings(v) -> bool:
    if isinstance(v, (str, bytes, dict)):
        return False
    try:
        return all(isinstance(x, (str, np.str_)) for x in v)
    except TypeError:
        return False


# pybind11 type text -> (check, what it must be)
_CHECKS = {
    "float": (_is_number, "a number"),
    "int": (_is_integer, "an integer"),
    "bool": (lambda v: isinstance(v, (bool, np.bool_)), "True or False"),
    "str": (lambda v: isinstance(v, str), "a str"),
    "List[float]": (_is_numbers_1d, "a 1-D sequence of numbers"),
    "list[float]": (_is_numbers_1d, "a 1-D sequence of numbers"),
    "List[str]": (_is_strings, "a list of str"),
    "list[str]": (_is_strings, "a list of str"),
}


def _split_top(text: str) -> list[str]:
    """Splits at the commas outside brackets and quotes."""
    parts, depth, quote, cur = [], 0, "", ""
    for c in text:
        if quote:
            quote = "" if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "[(<{":
            depth += 1
        elif c in "])>}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        cur += c
    parts.append(cur)
    return parts


def _signature(fn) -> list[tuple[str, str]]:
    """[(name, type)] from the first line of a pybind11 docstring: "f(a: float = 1.0, ...) -> x"."""
    doc = (fn.__doc__ or "").strip().splitlines()
    if not doc or "(" not in doc[0]:
        return []
    first = doc[0]
    inner = first[first.find("(") + 1:first.rfind(") ->") if ") ->" in first else first.rfind(")")]
    out = []
    for part in _split_top(inner):
        name, _, rest = part.strip().partition(":")
        out.append((name.strip(), rest.split(" = ")[0].strip()))
    return out


def checked(fn):
    """fn with its arguments checked against its pybind11 signature before the call."""
    sig = _signature(fn)
    names = [n for n, _ in sig]
    types = dict(sig)

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        given = list(zip(names, args)) + list(kwargs.items())
        for name, value in given:
            check = _CHECKS.get(types.get(name, ""))
            if check is not None and not check[0](value):
                raise TypeError(f"{fn.__name__}(): {name} must be {check[1]}{_unit(name)}, "
                                f"not {_what(value)}")
        return fn(*args, **kwargs)

    return wrapper
