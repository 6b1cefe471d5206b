"""gmasim: temperature-dependent giant magnetostrictive actuator simulator.

The numerical core is the C++ library (extension module ``gmasim._gmasim``); this package
adds plotting helpers (``gmasim.plots``). Units are SI and named in every key
(``stroke_um``, ``temperature_C``, ``current_A``).

    import gmasim
    m = gmasim.Model()                       # the built-in MDMA model
    r = gmasim.simulate(m, temperature_C=70, current_pp_A=8, frequency_Hz=10)
    r["metrics"]["stroke_um"], r["series"]["y_um"]   # print(r): a one-line summary
    r = gmasim.simulate(m, current_A=i_samples, current_dt_s=1e-4)  # a sampled current [A, s]
    r = gmasim.simulate(m, waveform=(t_s, current_A))               # or a (t, i) pair [s, A]
    s = gmasim.sweep(m, temperatures_C=[20, 70])   # {'meta', 'points': {column: ndarray}}
    gmasim.plots.sweep_vs_temperature(s["points"])
    st = gmasim.Stepper(m, temperature_C=20, dt_s=1e-5)  # sample by sample (docs/c_api.md)
    y_um = st.step(1.5)
    s = gmasim.sensitivity(m, params=["material.Ms_A_per_m"], claims=["stroke_drop_8A"])
    s["derivative"]   # (quantities x parameters): d claim / d ln parameter
    sys = gmasim.linearize(m, temperature_C=70)    # scipy.signal.StateSpace, current -> y [m]
    df = gmasim.frame(r)                           # pandas DataFrame of the series (t_s index)

Errors: gmasim.InputError (a ValueError: a value out of range, with the rule), TypeError (an
argument of the wrong type, named), gmasim.DivergenceError (an ArithmeticError: the run
diverged; simulate() and Stepper.step() both raise it, and simulate's exception carries the
partial run as its ``result`` attribute). Values far outside Terfenol-D's known range and
temperatures outside a model's validated range give a UserWarning.
"""
from ._gmasim import *  # noqa: F401,F403
from ._gmasim import (FREEZE_LAWS, DivergenceError, InputError, Model, Stepper, ablate, claims,  # noqa: F401
                      compensate, frf, parameter_table, params_vs_temperature, simulate, sweep,
                      thermal_expansion, track)
from ._gmasim import __git_describe__, __version__  # noqa: F401
from . import plots  # noqa: F401
from ._sensitivity import fit_parameters, sensitivity  # noqa: F401
from ._linearize import linearize  # noqa: F401
from ._arguments import checked as _checked
from ._results import SimulationResult, as_result as _as_result, frame  # noqa: F401

# Every function of the extension module checks its arguments' types first, so that a wrong
# one is a TypeError naming the argument and the expected type (issue 19, item 11).
simulate, sweep, frf, track, compensate, ablate, params_vs_temperature, thermal_expansion, claims = (
    _checked(f) for f in (simulate, sweep, frf, track, compensate, ablate, params_vs_temperature,
                          thermal_expansion, claims))
simulate = _as_result(simulate)

__all__ = ["Model", "Stepper", "simulate", "sweep", "frf", "track", "compensate", "ablate",
           "params_vs_temperature", "parameter_table",
           "thermal_expansion", "claims", "sensitivity", "fit_parameters", "linearize", "plots", "InputError",
           "DivergenceError", "FREEZE_LAWS", "SimulationResult", "frame"]
