#!/usr/bin/env python3
"""AllanTools' own overlapping ADEV of a GL-2D pulse file, as a user of it computes one, for the
side-by-side row of bench/run-benchmarks.sh: import allantools (from the checkout given, which is not
part of rwcalc), load the text with numpy.loadtxt as bench/numpy_oavar.py does, and call
allantools.oadev on the phase with its octave grid.

Usage: allantools_oadev.py ALLANTOOLS_DIR FILE [--rate HZ] [--scale ARCSEC] [--print]
ALLANTOOLS_DIR is a checkout of AllanTools (the directory holding the allantools package); it needs
NumPy and SciPy (Debian python3-numpy, python3-scipy). Prints its stage timings to stderr; with
--print, tau and OADEV (deg/h) to stdout.
"""
import argparse
import os
import sys
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("allantools_dir")
    ap.add_argument("file")
    ap.add_argument("--rate", type=float, default=400.0)
    ap.add_argument("--scale", type=float, default=0.92)
    ap.add_argument("--print", action="store_true")
    a = ap.parse_args()
    t0 = time.perf_counter()
    sys.path.insert(0, os.path.abspath(a.allantools_dir))
    sys.path.insert(1, os.path.dirname(os.path.abspath(__file__)))
    import allantools  # noqa: E402 (its own import, SciPy's among them, is part of its cost)
    from numpy_oavar import load_pulses, phase_of  # noqa: E402

    t1 = time.perf_counter()
    pulses = load_pulses(a.file)
    t2 = time.perf_counter()
    taus, dev, _, _ = allantools.oadev(phase_of(pulses, a.scale), rate=a.rate, data_type="phase", taus="octave")
    t3 = time.perf_counter()
    print(f"allantools: import {t1 - t0:.3f} s, load {t2 - t1:.3f} s, oadev {t3 - t2:.3f} s for {len(taus)} tau",
          file=sys.stderr)
    if a.print:
        for t, d in zip(taus, dev):
            print(f"{t:.6g} {d:.9g}")


if __name__ == "__main__":
    main()
