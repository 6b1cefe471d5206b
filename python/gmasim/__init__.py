"""gmasim: temperature-dependent giant magnetostrictive actuator simulator.

The numerical core is the C++ library (extension module ``gmasim._gmasim``); this package
adds plotting helpers (``gmasim.plots``). Units are SI and named in every key
(``stroke_um``, ``temperature_C``, ``current_A``).

    import gmasim
    m = gmasim.Model()                       # the built-in MDMA model
    r = gmasim.simulate(m, temperature_C=70, current_pp_A=8, frequency_Hz=10)
    r["metrics"]["stroke_um"], r["series"]["y_um"]
    s = gmasim.sweep(m, temperatures_C=[20, 70])   # {'meta', 'points': {column: ndarray}}
    gmasim.plots.sweep_vs_temperature(s["points"])
"""
from ._gmasim import *  # noqa: F401,F403
from ._gmasim import (DivergenceError, InputError, Model, ablate, claims, compensate,  # noqa: F401
                      frf, params_vs_temperature, simulate, sweep, thermal_expansion, track)
from . import plots  # noqa: F401

__all__ = ["Model", "simulate", "sweep", "frf", "track", "compensate", "ablate", "params_vs_temperature",
           "thermal_expansion", "claims", "plots", "InputError", "DivergenceError"]
