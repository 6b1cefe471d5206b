#!/usr/bin/env python3
"""Shape of a quasi-static strain-vs-field loop (issue 21, item 2), on the butterfly's right
wing (strain rising with the field, from each branch's strain minimum): the loop width (field
between the rising and the falling branch at equal strain) at fractions of the wing's strain
span, the knee (the field where the rising branch reaches 80 % of the span) and the field of
steepest rise. Reads gmasim measurement CSV files (field_A_per_m, strain_ppm; one period,
starting at the field minimum; a loop at negative fields is mirrored). Usage: loop_shape.py FILE [FILE ...]"""
import csv
import sys


def read(path):
    rows = [r for r in open(path) if not r.startswith("#")]
    rd = csv.DictReader(rows)
    H, S = [], []
    for r in rd:
        H.append(float(r["field_A_per_m"]))
        S.append(float(r["strain_ppm"]))
    return H, S


def branch_at(H, S, s):
    """Field where the branch (H monotone along it) first reaches strain s (linear)."""
    for i in range(len(S) - 1):
        a, b = S[i], S[i + 1]
        if (a - s) * (b - s) <= 0 and a != b:
            return H[i] + (s - a) / (b - a) * (H[i + 1] - H[i])
    return float("nan")


def wing(H, S):
    """The part of a branch (in the order of rising field) from its strain minimum on: the
    right wing of a butterfly (strain rising with the field)."""
    j = min(range(len(S)), key=lambda i: S[i])
    return H[j:], S[j:]


def shape(path):
    H, S = read(path)
    if max(H) < -0.5 * min(H):  # a loop at negative fields (-6..0 A): its mirror image, from its
        H = [-h for h in H]  # field minimum, so the wing rises with the field like the others
        j = min(range(len(H)), key=lambda i: H[i])
        H, S = H[j:] + H[:j], S[j:] + S[:j]
    k = max(range(len(H)), key=lambda i: H[i])
    up_H, up_S = wing(H[: k + 1], S[: k + 1])
    dn_H, dn_S = wing(H[k:][::-1], S[k:][::-1])
    lo, hi = max(min(up_S), min(dn_S)), min(max(up_S), max(dn_S))
    out = {"file": path, "span_ppm": max(S) - min(S), "widths_kA_per_m": []}
    for f in (0.2, 0.4, 0.6, 0.8, 0.9):
        s = lo + f * (hi - lo)
        w = branch_at(up_H, up_S, s) - branch_at(dn_H, dn_S, s)
        out["widths_kA_per_m"].append((f, w / 1e3))
    out["knee_kA_per_m"] = branch_at(up_H, up_S, lo + 0.8 * (hi - lo)) / 1e3
    slopes = [(up_S[i + 1] - up_S[i]) / (up_H[i + 1] - up_H[i]) for i in range(len(up_H) - 1)
              if up_H[i + 1] != up_H[i]]
    i = max(range(len(slopes)), key=lambda j: slopes[j])
    out["steepest_kA_per_m"] = 0.5 * (up_H[i] + up_H[i + 1]) / 1e3
    return out


for p in sys.argv[1:]:
    o = shape(p)
    widths = ", ".join(f"{int(f * 100)}%: {w:.2f}" for f, w in o["widths_kA_per_m"])
    print(f'{o["file"]}: span {o["span_ppm"]:.1f} ppm; width [kA/m] at strain {widths}; '
          f'knee (80 %) {o["knee_kA_per_m"]:.2f} kA/m; steepest {o["steepest_kA_per_m"]:.2f} kA/m')
