#!/usr/bin/env python3
"""Speed of a Python controller in the loop (issue 40's target: the paper's PID as a Python
callback, at a 10 kHz sample rate, at least 20x faster than real time on one core).

    PYTHONPATH=build/ci/python /usr/bin/python3 bench/python_controller.py [--repeats 5]

Runs gmasim.track on the built-in model at 20 degC, 10 um, 10 Hz, 4 periods (0.4 s of loop time,
4000 controller samples, 40,000 plant steps of 10 us) with the built-in PID and with the same PID
as a Python callback (python/tests/test_controller.py's PaperPid), one thread, and prints the
median wall and CPU time and the real-time factor (loop time / time) of each (the CPU time is
the steadier on a shared machine). A benchmark, not a
test: the figure goes in the note.
"""
import argparse
import pathlib
import statistics
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "python" / "tests"))
import gmasim  # noqa: E402
from test_controller import PaperPid  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    m = gmasim.Model()
    grid = dict(temperatures_C=[20.0], amplitudes_um=[10.0], frequencies_Hz=[10.0], threads=1)
    loop_s = 4 / 10.0
    for name, extra in (("built-in PID", {}), ("Python callback PID", {"controller": PaperPid()})):
        walls, cpus = [], []
        for _ in range(a.repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            gmasim.track(m, **grid, **extra)
            walls.append(time.perf_counter() - t0)
            cpus.append(time.process_time() - c0)
        w, c = statistics.median(walls), statistics.median(cpus)
        print(f"{name:22s} wall {w * 1e3:7.1f} ms, CPU {c * 1e3:7.1f} ms for {loop_s:.1f} s of loop: "
              f"{loop_s / w:6.1f}x real time (wall), {loop_s / c:6.1f}x (CPU)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
