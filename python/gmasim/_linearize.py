"""gmasim.linearize: the small-signal plant as a scipy.signal.StateSpace (issue 40 item 1)."""
from __future__ import annotations

import numpy as np

from . import _gmasim


def linearize(model, temperature_C: float = 20.0, bias_A: float = 1.0, output: str = "y",
              amplitude_A: float = 0.0, frequencies_Hz=(10.0, 100.0, 1000.0)):
    """The plant current -> ``output`` about a DC bias, as a ``scipy.signal.StateSpace``.

    ``output``: ``"y"`` (the sensor's displacement [m]) or ``"B"`` (the induction coil's flux
    density [T], consistent magnetic state only); ``"all"`` keeps both rows of C and D. The input
    is the current's change [A]; the states are SI (``sys.states``, ``sys.state_units``: the
    rods' fields [A/m], displacements [m] and velocities [m/s], then the sensor mount's two
    states). The returned object also carries ``poles``, ``zeros_y``, ``dc_gain``,
    ``temperature_C`` and ``bias_A`` (gmasim's own, beside scipy's ``sys.poles``). With
    ``amplitude_A`` > 0 it also carries ``describing_function``: the large-signal gain [um/A]
    and phase [deg] at that current amplitude about the bias for each of ``frequencies_Hz``,
    beside the small-signal ones (``gmasim linearize --amplitude``), as a dict of arrays.
    The plant split at the sensor mount, so that another sensor model can replace it:
    ``sys.stack`` (current [A] -> ``y_stack``, ``q`` [m], and ``B``), ``sys.mount`` (q [m] ->
    ``dy`` [m]; None without a mount) and ``sys.interconnection`` ("y = y_stack + dy" on the
    housing's recoil, "y = dy" when the probe rides on the output, "y = y_stack" without one).

        sys = gmasim.linearize(gmasim.Model(), temperature_C=70)
        H = sys.C @ np.linalg.solve(2j * np.pi * f * np.eye(len(sys.A)) - sys.A, sys.B)

    scipy's freqresp and bode of a StateSpace go through a transfer function's polynomials,
    ill-conditioned for this plant (poles up to 1e5 1/s: scipy warns BadCoefficients, ~1e-9
    relative); C (jwI - A)^-1 B as above is exact to rounding.
    """
    from scipy import signal

    d = _gmasim._linearize(model, float(temperature_C), float(bias_A), float(amplitude_A),
                           [float(f) for f in frequencies_Hz])
    if output == "all":
        rows = list(range(len(d["outputs"])))
    elif output in d["outputs"]:
        rows = [d["outputs"].index(output)]
    else:
        raise _gmasim.InputError(
            f"linearize(): output must be one of {d['outputs'] + ['all']}, not {output!r}")
    sys = signal.StateSpace(np.asarray(d["A"]), np.asarray(d["B"]), np.asarray(d["C"])[rows],
                            np.asarray(d["D"])[rows])
    sys.states = list(d["states"])
    sys.state_units = list(d["state_units"])
    sys.outputs = [d["outputs"][k] for k in rows]
    sys.output_units = [d["output_units"][k] for k in rows]
    sys.gmasim_poles = np.asarray(d["poles"])
    sys.zeros_y = np.asarray(d["zeros_y"])
    sys.dc_gain = np.asarray(d["dc_gain"])[rows]
    sys.temperature_C = d["temperature_C"]
    sys.bias_A = d["bias_A"]
    if "describing_function" in d:
        sys.describing_function = d["describing_function"]
    # The plant split at the sensor mount: sys.stack (current -> y_stack, q[, B]) and sys.mount
    # (q -> dy; None without a mount), put together as sys.interconnection says.
    blocks = []
    for b in d["blocks"]:
        bs = signal.StateSpace(np.asarray(b["A"]), np.asarray(b["B"]), np.asarray(b["C"]),
                               np.asarray(b["D"]))
        for key in ("states", "state_units", "outputs", "output_units", "input", "input_unit"):
            setattr(bs, key, b[key])
        blocks.append(bs)
    sys.stack = blocks[0]
    sys.mount = blocks[1] if len(blocks) > 1 else None
    sys.interconnection = d["interconnection"]
    return sys
