#!/usr/bin/env python3
"""Copies of scripts/golden.sh's inputs with their floating values moved by a relative REL.

Usage: perturb_inputs.py REL CHECKOUT DEST
  CHECKOUT/data/gl2d/*.csv.gz      -> DEST/data/gl2d/ (header's rate_hz and scale moved; the pulse
                                      counts are integers and stay)
  CHECKOUT/../shared/data/...      -> DEST/../shared/data/... (every decimal sample moved, alternately
                                      up and down), for the reference and ADIS16405 inputs golden.sh reads
"""
import gzip
import os
import re
import sys

DECIMAL = re.compile(r"(?<![\w.])[-+]?\d*\.\d+(?:[eE][-+]?\d+)?")
SHARED_INPUTS = ["reference/nbs14_riley/nbs14_1000point_freq.txt",
                 "real/imudata_adis16405/adis_16405_imu1.csv.gz",
                 "real/imudata_adis16405/adis_16405_imu2.csv.gz"]


def opener(path, mode):
    """gzip for .gz (level 1 when writing: the copies live for one test run), else a plain file."""
    if not path.endswith(".gz"):
        return open(path, mode, encoding="utf-8")
    return gzip.open(path, mode, encoding="utf-8", **({"compresslevel": 1} if "w" in mode else {}))


def copy_lines(src, dst, change):
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    with opener(src, "rt") as f, opener(dst, "wt") as g:
        for i, line in enumerate(f):
            g.write(change(i, line))


def copy_header(src, dst, change):
    """Like copy_lines for a change that touches only the leading comment lines: the millions of
    sample lines after them are copied as one block (line by line took a minute per run)."""
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    with gzip.open(src, "rt", encoding="utf-8") as f:
        text = f.read()
    end = 0
    while text.startswith("#", end):
        end = text.index("\n", end) + 1
    head = "".join(change(i, line) for i, line in enumerate(text[:end].splitlines(True)))
    with gzip.open(dst, "wt", encoding="utf-8", compresslevel=1) as g:
        g.write(head)
        g.write(text[end:])


def main(rel, checkout, dest):
    up, down = 1 + rel, 1 - rel

    def header(i, line):  # GL-2D: the header's floating metadata, not the integer counts
        m = re.match(r"# (rate_hz|scale_arcsec_per_pulse): (\S+)", line)
        return f"# {m.group(1)}: {float(m.group(2)) * up!r}\n" if m else line

    def samples(i, line):  # comments stay; each decimal sample moves, alternately up and down
        if line.startswith("#"):
            return line
        k = up if i % 2 else down
        if "," in line:  # CSV: field by field, several times faster than the regular expression
            return ",".join(repr(float(f) * k) if "." in f else f for f in line.rstrip("\n").split(",")) + "\n"
        return DECIMAL.sub(lambda m: repr(float(m.group(0)) * k), line)

    gl = os.path.join(checkout, "data", "gl2d")
    for name in sorted(os.listdir(gl)):
        if name.endswith(".csv.gz"):
            copy_header(os.path.join(gl, name), os.path.join(dest, "data", "gl2d", name), header)
    shared = os.path.join(checkout, "..", "shared", "data")
    for rel_path in SHARED_INPUTS:
        src = os.path.join(shared, rel_path)
        if os.path.exists(src):
            copy_lines(src, os.path.join(dest, "..", "shared", "data", rel_path), samples)


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(float(sys.argv[1]), sys.argv[2], sys.argv[3])
