#!/usr/bin/python3
"""Runs every command of README.md's IMU section as written, from a directory laid out like a fresh
clone after the quick start: the repository's data/ and build/rwcalc, nothing else (no ../shared).
Each command must succeed, and every file under data/ it names must be in the repository (tracked by
git when the source is a git work tree), so that a clone has it.

Usage: readme_imu_commands.py SOURCE_DIR RWCALC"""
import os
import pathlib
import re
import shlex
import subprocess
import sys
import tempfile


def section_commands(readme):
    text = readme.read_text(encoding="utf-8")
    m = re.search(r"^## IMU\n(.*?)(?=^## )", text, re.S | re.M)
    if not m:
        sys.exit(f"{readme}: no '## IMU' section")
    commands = []
    for block in re.findall(r"^```sh\n(.*?)^```", m.group(1), re.S | re.M):
        for command in block.replace("\\\n", " ").splitlines():
            if command.strip() and not command.lstrip().startswith("#"):
                commands.append(command.strip())
    return commands


def tracked(source, path):
    if not (source / ".git").exists():
        return True
    return subprocess.run(["git", "-C", str(source), "ls-files", "--error-unmatch", path],
                          capture_output=True).returncode == 0


def main():
    source, rwcalc = pathlib.Path(sys.argv[1]).resolve(), pathlib.Path(sys.argv[2]).resolve()
    commands = section_commands(source / "README.md")
    if len(commands) < 3:
        sys.exit(f"README.md's IMU section has {len(commands)} commands; expected its examples (at least 3)")
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        clone = pathlib.Path(tmp)
        (clone / "data").symlink_to(source / "data")
        (clone / "build").mkdir()
        (clone / "build" / "rwcalc").symlink_to(rwcalc)
        for command in commands:
            words = shlex.split(command)
            if words[0] != "./build/rwcalc":
                failures.append(f"{command}: does not start with ./build/rwcalc")
                continue
            # A path out of the clone: up from it, or an absolute path that exists here (a ROS
            # topic such as /imu/data is no path).
            outside = [w for w in words if w.startswith(("../", "~")) or (w.startswith("/") and os.path.exists(w))]
            missing = [w for w in words if w.startswith("data/") and not (
                (source / w).exists() and tracked(source, w))]
            if outside or missing:
                failures.append(f"{command}: names files a clone does not have: {outside + missing}")
                continue
            r = subprocess.run(command, shell=True, cwd=clone, capture_output=True, text=True,
                               env=dict(os.environ, RWCALC_LANG="en"), timeout=600)
            print(f"$ {command}\n  exit status {r.returncode}")
            if r.returncode != 0:
                failures.append(f"{command}: exit status {r.returncode}\n{r.stderr}")
        for name in ("imu.yaml", "vins.yaml", "openvins.yaml", "imu.png", "imu-report/index.html"):
            if not (clone / name).is_file():
                failures.append(f"{name}: not written by the README's IMU commands")
    if failures:
        print("\n".join(failures), file=sys.stderr)
        sys.exit(1)
    print(f"{len(commands)} commands of README.md's IMU section ran as written")


if __name__ == "__main__":
    main()
