#!/usr/bin/env python3
"""Baseline for docs/performance.md: the fully overlapping Allan deviation of a GL-2D pulse file
computed the straightforward NumPy way (as AllanTools' oadev does it): load the text with
numpy.loadtxt, form the phase by a cumulative sum, and for each cluster size m sum the squared
second differences x[k+2m] - 2x[k+m] + x[k] over k.

Usage: numpy_oavar.py FILE [--grid octave|dense] [--rate HZ] [--scale ARCSEC] [--print]
Prints one line per stage timing to stderr; with --print, tau and OADEV (deg/h) to stdout.
"""
import argparse
import sys
import time

import numpy as np


def cluster_sizes(n_phase, grid):
    """Octave: m = 1, 2, 4, ... up to (N-1)/2; dense: ~20 log-spaced distinct m per decade up to N/10."""
    if grid == "octave":
        top = (n_phase - 1) // 2
        return 2 ** np.arange(int(np.log2(top)) + 1)
    top = max(1, (n_phase - 1) // 10)
    ms = np.unique(np.round(np.logspace(0, np.log10(top), int(20 * np.log10(top)) + 1)).astype(np.int64))
    return ms[ms <= top]


def oadev(phase, tau0, ms):
    """Fully overlapping Allan deviation at each m (phase in arcsec, result in arcsec/s = deg/h)."""
    out = np.empty(len(ms))
    n = len(phase)
    for i, m in enumerate(ms):
        d = phase[2 * m:] - 2.0 * phase[m:n - m] + phase[:n - 2 * m]
        out[i] = np.sqrt(np.sum(d * d) / (2.0 * (m * tau0) ** 2 * (n - 2 * m)))
    return out


def load_pulses(path):
    """The pulse counts of a pulse file: its '# key: value' lines and 'pulses' header row skipped."""
    with open(path, "rb") as f:
        header_lines = 0
        for line in f:
            s = line.strip()
            if s.startswith(b"#") or s == b"pulses":
                header_lines += 1
                continue
            break
    return np.loadtxt(path, dtype=np.int64, skiprows=header_lines, ndmin=1)


def phase_of(pulses, scale):
    """The phase in arcsec from the pulse counts (C_0 = 0)."""
    return np.concatenate(([0.0], np.cumsum(pulses, dtype=np.float64))) * scale


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--grid", choices=["octave", "dense"], default="octave")
    ap.add_argument("--rate", type=float, default=400.0)
    ap.add_argument("--scale", type=float, default=0.92)
    ap.add_argument("--print", action="store_true")
    a = ap.parse_args()
    t0 = time.perf_counter()
    pulses = load_pulses(a.file)
    t1 = time.perf_counter()
    phase = phase_of(pulses, a.scale)
    ms = cluster_sizes(len(phase), a.grid)
    dev = oadev(phase, 1.0 / a.rate, ms)
    t2 = time.perf_counter()
    print(f"numpy: load {t1 - t0:.3f} s, oadev {t2 - t1:.3f} s for {len(ms)} tau ({a.grid})", file=sys.stderr)
    if a.print:
        for m, d in zip(ms, dev):
            print(f"{m / a.rate:.6g} {d:.9g}")


if __name__ == "__main__":
    main()
