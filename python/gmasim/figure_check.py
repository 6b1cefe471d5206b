"""An automated reading of a matplotlib figure: what a reader needs before the data.

:func:`problems` draws the figure (the Agg canvas, as :func:`gmasim.plots.save` would) and
returns one sentence per defect, using matplotlib's own text extents (every visible Text's
``get_window_extent`` with the figure's renderer):

- no title (an axes title or the figure's suptitle);
- an axes without an x or y label, or whose label has no unit in parentheses, e.g.
  "frequency (Hz)"; a categorical axis (text tick labels) needs no unit, a dimensionless
  quantity says "(-)" or "(%)"; shared axes may carry the label on a sibling; colorbars are
  checked for a label only;
- two visible texts whose extents overlap by more than ``tolerance_px`` in both directions
  (titles, axis labels, tick labels, legend texts and titles, annotations, figure texts);
- a legend that covers a plotted line (a sample of the line, 16 points per segment, inside the
  legend's frame);
- an axis offset label ("1e-7" above the axis: the unit should be scaled instead), and an
  annotation that runs outside its axes (into a neighbour, or clipped at the figure's edge);
- text under 6 pt; a legend over a tick label; a series of ours drawn with the paper's diamond
  marker (kept for the paper's values, gid "paper"); a heatmap row or column with no finite
  value; two panels that draw the same data.
A figure of several panels needs a title above them all (suptitle); one panel, its own.

:func:`check` raises :class:`FigureProblem` with all of them. :func:`gmasim.plots.save` runs
the check before it writes anything when the environment sets ``GMASIM_FIGURE_CHECK=1``
(the tests; a figure that fails is not written), and calls every function registered with
:func:`gmasim.plots.add_save_hook`.
"""
from __future__ import annotations

import re

import numpy as np
from matplotlib.legend import Legend
from matplotlib.lines import Line2D
from matplotlib.text import Text

_UNIT = re.compile(r"\([^()]*\)|\[[^\[\]]*\]")


class FigureProblem(AssertionError):
    """A figure a reader cannot read alone (the sentences in ``problems``)."""

    def __init__(self, name, found):
        self.problems = list(found)
        super().__init__(f"{name}: " + "; ".join(self.problems))


def _is_colorbar(ax) -> bool:
    return ax.get_label() == "<colorbar>" or hasattr(ax, "_colorbar")


def _has_content(ax) -> bool:
    return bool(ax.lines or ax.collections or ax.patches or ax.images or ax.texts)


def _categorical(labels) -> bool:
    for t in labels:
        s = t.get_text().replace("−", "-").strip()
        if not s or "$" in s:
            continue
        try:
            float(s)
        except ValueError:
            return True
    return False


def _visible_ticklabels(axis):
    """The tick labels matplotlib draws: ticks within the view interval, visible, non-empty."""
    if not axis.get_visible():
        return []
    lo, hi = sorted(axis.get_view_interval())
    span = hi - lo
    out = []
    for ticks, locs in ((axis.get_major_ticks(len(axis.get_majorticklocs())), axis.get_majorticklocs()),
                        (axis.get_minor_ticks(len(axis.get_minorticklocs())), axis.get_minorticklocs())):
        for tick, loc in zip(ticks, locs):
            if not (lo - 1e-9 * span <= loc <= hi + 1e-9 * span):
                continue
            for lab in (tick.label1, tick.label2):
                if lab.get_visible() and lab.get_text():
                    out.append(lab)
    return out


def _label_of(ax, which):
    get = "get_xlabel" if which == "x" else "get_ylabel"
    own = getattr(ax, get)()
    if own:
        return own
    shared = ax.get_shared_x_axes() if which == "x" else ax.get_shared_y_axes()
    return next((getattr(o, get)() for o in shared.get_siblings(ax) if getattr(o, get)()), "")


def _label_problems(fig) -> list[str]:
    out = []
    panels = [ax for ax in fig.axes if ax.get_visible() and not _is_colorbar(ax) and _has_content(ax)]
    suptitle = fig._suptitle is not None and bool(fig._suptitle.get_text())
    titled = any(ax.get_title(loc=loc) for ax in panels for loc in ("left", "center", "right"))
    hosts = {ax.bbox.bounds for ax in panels}  # a twin shares its host's box
    columns = {(round(b[0]), round(b[2])) for b in hosts}
    top = max(panels, key=lambda ax: ax.bbox.y1) if panels else None
    if len(columns) == 1 and top is not None and top.get_title():
        titled, hosts = True, {top.bbox.bounds}  # one column of panels (a Bode plot): the top one's title
    if len(hosts) > 1 and not suptitle:
        out.append("no title (a figure of several panels needs one above them all)")
    elif not (suptitle or titled):
        out.append("no title")
    for n, ax in enumerate(fig.axes):
        if not ax.get_visible() or not ax.axison:
            continue
        name = ax.get_title() or f"axes {n}"
        if _is_colorbar(ax):
            if not (ax.get_ylabel() or ax.get_xlabel()):
                out.append(f"colorbar of {name}: no label")
            continue
        if not _has_content(ax) and not ax.get_ylabel():
            continue
        for which, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            ticks = _visible_ticklabels(axis)
            if which == "x" and not any(t.get_visible() for t in ticks) and not ax.get_xlabel():
                # an x axis without tick labels is shared with the panel below it
                shared = ax.get_shared_x_axes().get_siblings(ax)
                if len(shared) > 1:
                    continue
            label = _label_of(ax, which)
            if which == "x" and not label and ax.get_ylabel() and len(fig.axes) > 1:
                # a twin (twinx) carries only its y label; the x axis is its host's
                if any(o is not ax and o.bbox.bounds == ax.bbox.bounds and o.get_xlabel() for o in fig.axes):
                    continue
            if not label:
                out.append(f"{name}: no {which} label")
            elif not _UNIT.search(label) and not _categorical(ticks):
                out.append(f"{name}: {which} label '{label}' has no unit in parentheses")
    return out


def _texts(fig):
    """Every visible, non-empty Text the figure draws, with a short name."""
    found = []

    def add(t, what):
        if isinstance(t, Text) and t.get_visible() and t.get_text().strip() and t.get_alpha() != 0:
            found.append((t, what))

    add(fig._suptitle, "suptitle")
    for t in fig.texts:
        if t is not fig._suptitle and t is not getattr(fig, "_supxlabel", None) \
                and t is not getattr(fig, "_supylabel", None):
            add(t, "figure text")
    add(getattr(fig, "_supxlabel", None), "x label")
    add(getattr(fig, "_supylabel", None), "y label")
    for leg in fig.legends:
        for t in leg.get_texts():
            add(t, "legend")
        add(leg.get_title(), "legend title")
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for loc, t in (("left", ax._left_title), ("center", ax.title), ("right", ax._right_title)):
            add(t, "title")
        if ax.axison:
            for axis, w in ((ax.xaxis, "x label"), (ax.yaxis, "y label")):
                if axis.get_visible():
                    add(axis.label, w)
            for t in _visible_ticklabels(ax.xaxis):
                add(t, "x tick")
            for t in _visible_ticklabels(ax.yaxis):
                add(t, "y tick")
            add(ax.xaxis.get_offset_text(), "x offset")
            add(ax.yaxis.get_offset_text(), "y offset")
        for t in ax.texts:
            add(t, "annotation")
        leg = ax.get_legend()
        if leg is not None and leg.get_visible():
            for t in leg.get_texts():
                add(t, "legend")
            add(leg.get_title(), "legend title")
    return found


def _layout_problems(fig, renderer) -> list[str]:
    """Offset labels ('1e-7' above an axis: scale the unit instead) and annotations that run
    outside their axes (into a neighbour, or clipped at the figure's edge)."""
    out = []
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for axis, which in ((ax.xaxis, "x"), (ax.yaxis, "y")):
            off = axis.get_offset_text()
            if axis.get_visible() and off.get_visible() and off.get_text().strip():
                out.append(f"{ax.get_title() or 'an axes'}: {which} axis offset label "
                           f"'{off.get_text()}' (scale the unit instead)")
        box = ax.get_window_extent(renderer)
        for t in ax.texts:
            if not t.get_visible() or not t.get_text().strip():
                continue
            e = t.get_window_extent(renderer)
            if e.x0 < box.x0 - 1 or e.x1 > box.x1 + 1 or e.y0 < box.y0 - 1 or e.y1 > box.y1 + 1:
                out.append(f"annotation '{t.get_text()[:40]}' runs outside its axes "
                           f"'{ax.get_title() or 'an axes'}'")
    return out


def _overlap_problems(fig, renderer, tolerance_px) -> list[str]:
    texts = _texts(fig)
    boxes = np.array([t.get_window_extent(renderer).extents for t, _ in texts]).reshape(-1, 4)
    out = []
    for i in range(len(texts)):
        x0, y0, x1, y1 = boxes[i]
        dx = np.minimum(x1, boxes[i + 1:, 2]) - np.maximum(x0, boxes[i + 1:, 0])
        dy = np.minimum(y1, boxes[i + 1:, 3]) - np.maximum(y0, boxes[i + 1:, 1])
        for j in np.nonzero((dx > tolerance_px) & (dy > tolerance_px))[0]:
            (a, wa), (b, wb) = texts[i], texts[i + 1 + j]
            out.append(f"{wa} '{a.get_text()[:40]}' overlaps {wb} '{b.get_text()[:40]}'")
    return out


def _legend_cover_problems(fig, renderer) -> list[str]:
    out = []
    for ax in fig.axes:
        leg = ax.get_legend()
        if not isinstance(leg, Legend) or not leg.get_visible():
            continue
        box = leg.get_window_extent(renderer)
        for ln in ax.lines:
            if not isinstance(ln, Line2D) or not ln.get_visible() or ln.get_label().startswith("_child"):
                continue
            xy = np.column_stack([np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)])
            xy = xy[np.all(np.isfinite(xy), axis=1)]
            if len(xy) == 0:
                continue
            pts = ln.get_transform().transform(xy)
            if ln.get_linestyle() not in ("None", "", " ") and len(pts) > 1:
                s = np.linspace(0.0, 1.0, 16)[:, None, None]
                pts = (pts[:-1] * (1 - s) + pts[1:] * s).reshape(-1, 2)
            ab = ax.get_window_extent(renderer)
            inside_ax = ((pts[:, 0] >= ab.x0) & (pts[:, 0] <= ab.x1) & (pts[:, 1] >= ab.y0) & (pts[:, 1] <= ab.y1))
            hit = inside_ax & (pts[:, 0] > box.x0) & (pts[:, 0] < box.x1) & (pts[:, 1] > box.y0) & (pts[:, 1] < box.y1)
            if np.any(hit):
                label = ln.get_label() if not ln.get_label().startswith("_") else "a line"
                out.append(f"the legend of '{ax.get_title() or 'an axes'}' covers '{label}'")
                break
    return out


MIN_FONT_PT = 6.0  # smaller text is unreadable at the figures' 130 dpi and in print


def _small_text_problems(fig) -> list[str]:
    """Text under MIN_FONT_PT points."""
    return [f"{what} '{t.get_text()[:40]}' is {t.get_fontsize():.3g} pt, under {MIN_FONT_PT:g} pt"
            for t, what in _texts(fig) if t.get_fontsize() < MIN_FONT_PT]


def _legends(fig):
    out = [leg for leg in fig.legends if leg.get_visible()]
    for ax in fig.axes:
        leg = ax.get_legend()
        if ax.get_visible() and isinstance(leg, Legend) and leg.get_visible():
            out.append(leg)
    return out


def _legend_tick_problems(fig, renderer, tolerance_px) -> list[str]:
    """A legend's frame over a tick label of any axes (it hides the scale)."""
    out = []
    for leg in _legends(fig):
        box = leg.get_window_extent(renderer)
        for ax in fig.axes:
            if not ax.get_visible() or not ax.axison:
                continue
            for axis in (ax.xaxis, ax.yaxis):
                for t in _visible_ticklabels(axis):
                    if not t.get_visible() or not t.get_text().strip():
                        continue
                    e = t.get_window_extent(renderer)
                    if min(box.x1, e.x1) - max(box.x0, e.x0) > tolerance_px and \
                            min(box.y1, e.y1) - max(box.y0, e.y0) > tolerance_px:
                        out.append(f"a legend covers the tick label '{t.get_text()}' of "
                                   f"'{ax.get_title() or 'an axes'}'")
                        break
    return out


PAPER_GID = "paper"  # the gid of the paper's markers (gmasim.plots._mark_paper)


def _paper_marker_problems(fig) -> list[str]:
    """A series of ours drawn with the paper's marker (the diamond), in a plot or a legend."""
    out = []
    for ax in fig.axes:
        for ln in ax.lines:
            if ln.get_visible() and ln.get_marker() == "D" and ln.get_gid() != PAPER_GID:
                label = ln.get_label() if not ln.get_label().startswith("_") else "a series"
                out.append(f"'{label}' in '{ax.get_title() or 'an axes'}' uses the paper's "
                           "diamond marker")
    for leg in _legends(fig):  # a legend's handles are copies (no gid): the entry's text says
        handles = getattr(leg, "legend_handles", None) or getattr(leg, "legendHandles", [])
        for h, t in zip(handles, leg.get_texts()):
            if isinstance(h, Line2D) and h.get_marker() == "D" and \
                    not t.get_text().startswith(PAPER_GID):
                out.append(f"the legend entry '{t.get_text()[:40]}' uses the paper's diamond marker")
    return out


def _empty_heatmap_problems(fig) -> list[str]:
    """A heatmap row (or column) with no finite value: an empty band that reads as data."""
    out = []
    for ax in fig.axes:
        for im in ax.images:
            a = np.ma.masked_invalid(np.ma.asarray(im.get_array(), dtype=float))
            if a.ndim != 2:
                continue
            for axis, what in ((1, "row"), (0, "column")):
                empty = np.nonzero(np.all(np.ma.getmaskarray(a), axis=axis))[0]
                if len(empty):
                    out.append(f"the heatmap of '{ax.get_title() or 'an axes'}' has empty "
                               f"{what}(s) {', '.join(map(str, empty[:5]))}")
    return out


def _panel_data(ax):
    """The panel's data, each series scaled by its largest magnitude: two panels that draw
    the same numbers in two units (µm and % of the stroke) have the same shapes."""
    def unit(v):
        v = np.asarray(v, float)
        m = np.nanmax(np.abs(v)) if v.size and np.any(np.isfinite(v)) else 0.0
        return v / m if m > 0 else v

    series = []
    for ln in ax.lines:
        y = np.asarray(ln.get_ydata(), float)
        if len(y) > 1:
            series.append(unit(y))
    for bars in ax.containers:  # each bar() call a series (error bars hold no patches)
        heights = [p.get_height() for p in getattr(bars, "patches", []) if hasattr(p, "get_height")]
        if len(heights) > 1:
            series.append(unit(heights))
    return series


def _same_data(a, b, rtol=1e-6) -> bool:
    if len(a) != len(b) or not a:
        return False
    for u, v in zip(a, b):
        if u.shape != v.shape:
            return False
        both = np.isfinite(u) & np.isfinite(v)
        if not np.array_equal(both, np.isfinite(u) | np.isfinite(v)):
            return False
        if np.any(np.abs(u[both] - v[both]) > rtol):
            return False
    return True


def _repeated_panel_problems(fig) -> list[str]:
    """Two panels that draw the same data, or the same data in another unit (the second tells
    the reader nothing new)."""
    out, seen = [], []
    for ax in fig.axes:
        if not ax.get_visible() or _is_colorbar(ax):
            continue
        data = _panel_data(ax)
        if not data:
            continue
        name = ax.get_title() or ax.get_ylabel() or "an axes"
        for other, other_name in seen:
            if _same_data(data, other):
                out.append(f"panels '{other_name}' and '{name}' draw the same data")
                break
        seen.append((data, name))
    return out


def _power_tick_problems(fig) -> list[str]:
    """A log axis that labels its ticks as m×10^0 (matplotlib's minor labels on an axis spanning
    less than a decade or two): write the plain number (issue 41: '2×10^0', '6×10^0')."""
    out = []
    for ax in fig.axes:
        for which, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            for lab in _visible_ticklabels(axis):
                t = lab.get_text()
                if "times" in t and "10^{0}" in t.replace(" ", ""):
                    out.append(f"'{ax.get_title() or 'an axes'}': {which} tick label '{t}' "
                               "(a power of ten to write as a plain number)")
                    break
    return out


def problems(fig, tolerance_px: float = 1.0) -> list[str]:
    """The defects of a figure (an empty list when it reads alone); draws it first."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    return (_label_problems(fig) + _overlap_problems(fig, renderer, tolerance_px)
            + _legend_cover_problems(fig, renderer) + _layout_problems(fig, renderer)
            + _small_text_problems(fig) + _legend_tick_problems(fig, renderer, tolerance_px)
            + _paper_marker_problems(fig) + _empty_heatmap_problems(fig)
            + _repeated_panel_problems(fig) + _power_tick_problems(fig))


def check(fig, name: str = "figure") -> None:
    """Raises FigureProblem listing the defects of ``fig``."""
    found = problems(fig)
    if found:
        raise FigureProblem(name, found)
