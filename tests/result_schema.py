#!/usr/bin/python3
"""Validates every JSON document rwcalc writes against docs/result.schema.json: analyze (a gyro in
its usual units and in rad/s, an accelerometer in µg and in m/s²), batch --json and each line of
batch --jsonl, merge --json, allan --json, imu --json and imu --report's imu.json, diagnose --json of
a gyro and of an accelerometer, all on the shipped records (data/gl2d, data/imu). Then checks what
the schema promises: a gyro's and an accelerometer's analysis have the same keys, documents that
break the schema are refused by it, and rwcalc's readers refuse another schema version or units
they cannot take, naming the file and what to do.

Usage: result_schema.py SOURCE_DIR RWCALC"""
import json
import pathlib
import re
import subprocess
import sys
import tempfile

import jsonschema

SOURCE, RWCALC = pathlib.Path(sys.argv[1]), sys.argv[2]
SCHEMA = json.loads((SOURCE / "docs" / "result.schema.json").read_text(encoding="utf-8"))
GL2D = [str(p) for p in sorted((SOURCE / "data" / "gl2d").glob("*.csv.gz"))]
IMU = str(SOURCE / "data" / "imu" / "mems_imu_sim.csv.gz")
failures = []


def fail(what):
    failures.append(what)
    print("FAIL:", what)


def run(*args, status=0):
    r = subprocess.run([RWCALC, *args], capture_output=True, text=True)
    if r.returncode != status:
        sys.exit(f"rwcalc {' '.join(args)}: exit {r.returncode}, expected {status}\n{r.stderr}")
    return r


def errors(doc, definition=None):
    """The schema's errors for `doc`: against $defs/definition, or the whole schema."""
    schema = SCHEMA if definition is None else {"$ref": f"#/$defs/{definition}", "$defs": SCHEMA["$defs"]}
    return list(jsonschema.Draft202012Validator(schema).iter_errors(doc))


def valid(name, doc, definition):
    for e in errors(doc, definition)[:5]:
        fail(f"{name}: {'.'.join(map(str, e.absolute_path))}: {e.message[:300]}")
    if errors(doc):
        fail(f"{name}: not valid against the schema's root (oneOf the documents)")
    if doc.get("schema_version") != 2:
        fail(f"{name}: schema_version is {doc.get('schema_version')!r}")


def key_paths(j, prefix=""):
    """Every key path of an object's objects, e.g. fit.N.si.unit (arrays, which may be empty, not entered)."""
    out = set()
    if isinstance(j, dict):
        for k, v in j.items():
            out.add(prefix + k)
            out |= key_paths(v, prefix + k + ".")
    return out


def main():
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="rwcalc-schema-"))
    docs = {}
    docs["analyze gyro"] = run("analyze", GL2D[0], "--json")
    docs["analyze gyro rad/s"] = run("analyze", IMU, "--column", "gyro_x_dps", "--output-unit", "rad/s", "--json")
    docs["analyze accelerometer"] = run("analyze", IMU, "--column", "acc_x_g", "--json")
    docs["analyze accelerometer m/s^2"] = run("analyze", IMU, "--column", "acc_y_g", "--output-unit", "m/s^2", "--json")
    docs["batch --json"] = run("batch", *GL2D, "--json")
    jsonl = run("batch", *GL2D, "--jsonl").stdout
    (tmp / "runs.jsonl").write_text(jsonl, encoding="utf-8")
    docs["merge --json"] = run("merge", str(tmp / "runs.jsonl"), "--json")
    docs["allan --json"] = run("allan", GL2D[0], "--json")
    docs["allan accelerometer"] = run("allan", IMU, "--column", "acc_z_g", "--json", "--tau", "decade")
    docs["imu --json"] = run("imu", IMU, "--json")
    docs["diagnose gyro"] = run("diagnose", GL2D[0], "--json", "--runs", "20")
    docs["diagnose accelerometer"] = run("diagnose", IMU, "--column", "acc_x_g", "--json", "--runs", "20")
    # A record with a line and a step, so that findings and their parameters are checked too.
    effects = tmp / "effects.csv.gz"
    run("simulate", "-o", str(effects), "--duration", "7200", "--rate", "40", "--arw", "0.001", "--bias-instability",
        "0.005", "--sinusoid", "0.0006:0.03", "--bias-step", "3000:0.06", "--seed", "5")
    docs["diagnose with findings"] = run("diagnose", str(effects), "--json")
    docs = {k: json.loads(r.stdout) for k, r in docs.items()}
    if [f["effect"] for f in docs["diagnose with findings"]["findings"]] != ["sinusoid", "bias_step"]:
        fail("diagnose of a record with a line and a step did not name both")
    run("imu", IMU, "--report", str(tmp / "report"))
    docs["imu --report imu.json"] = json.loads((tmp / "report" / "imu.json").read_text(encoding="utf-8"))
    lines = [json.loads(x) for x in jsonl.splitlines() if x.strip()]
    if len(lines) != len(GL2D):
        fail(f"batch --jsonl wrote {len(lines)} lines for {len(GL2D)} runs")
    for i, x in enumerate(lines):
        valid(f"batch --jsonl line {i + 1}", x, "analysis")
    for name, doc in docs.items():
        kind = name.split()[0]
        valid(name, doc, {"analyze": "analysis", "merge": "batch"}.get(kind, kind))

    # One schema: a gyro's and an accelerometer's analysis, in any unit, have the same keys (the
    # verdict and the reason it does not apply aside), and their units are fields.
    gyro, accel = docs["analyze gyro"], docs["analyze accelerometer"]
    aside = ("verdict", "not_applied_reason", "earth_rate_subtracted", "segments", "input.")
    def shared(doc):
        return {p for p in key_paths(doc) if not p.startswith(aside)}
    for name in ("analyze accelerometer", "analyze gyro rad/s", "analyze accelerometer m/s^2"):
        if shared(docs[name]) != shared(gyro):
            fail(f"{name} and analyze gyro differ in keys: {sorted(shared(docs[name]) ^ shared(gyro))[:10]}")
    unit_keys = [p for p in key_paths(accel) | key_paths(gyro) if re.search(r"_deg_per|_arcsec|_m_per_s|_ug\b", p)]
    if unit_keys:
        fail(f"keys naming a sensor unit: {unit_keys}")
    if (gyro["units"]["N"], accel["units"]["N"], docs["analyze gyro rad/s"]["units"]["N"]) != (
            "deg/sqrt(h)", "m/s/sqrt(h)", "rad/s/sqrt(Hz)"):
        fail(f"units.N: {gyro['units']['N']}, {accel['units']['N']}, {docs['analyze gyro rad/s']['units']['N']}")
    for name in ("analyze gyro", "analyze accelerometer"):
        for t in "QNBKR":
            if docs[name]["fit"][t]["unit"] != docs[name]["units"][t]:
                fail(f"{name}: fit.{t}.unit is not units.{t}")
    # The same numbers in another unit: N in rad/s/√Hz is N in °/√h times π/180/60.
    rad = docs["analyze gyro rad/s"]
    deg = run("analyze", IMU, "--column", "gyro_x_dps", "--json").stdout
    n_deg, n_rad = json.loads(deg)["fit"]["N"]["value"], rad["fit"]["N"]["value"]
    if abs(n_rad / (n_deg * 3.141592653589793 / 180 / 60) - 1) > 1e-9:
        fail(f"fit.N: {n_rad} rad/s/sqrt(Hz) is not {n_deg} deg/sqrt(h)")

    # Documents breaking the schema are refused by it.
    broken = {
        "a unit in a key": lambda d: d["fit"].__setitem__("N_deg_per_sqrt_h", d["fit"].pop("N")),
        "no units": lambda d: d.pop("units"),
        "schema version 1": lambda d: d.__setitem__("schema_version", 1),
        "a coefficient without its unit": lambda d: d["fit"]["B"].pop("unit"),
        "a string for a number": lambda d: d.__setitem__("mean_rate", "12.4"),
    }
    for what, edit in broken.items():
        doc = json.loads(json.dumps(gyro))
        edit(doc)
        if not errors(doc, "analysis") or not errors(doc):
            fail(f"the schema accepts an analysis with {what}")
    batch = json.loads(json.dumps(docs["batch --json"]))
    batch["runs"][1]["fit"]["Q"]["sigma"] = -1
    if not errors(batch, "batch"):
        fail("the schema accepts a batch whose run has a negative sigma")

    # rwcalc's readers refuse another schema version, and units they cannot take, naming the file.
    old = json.loads(json.dumps(gyro))
    del old["schema_version"]
    (tmp / "old.json").write_text(json.dumps(old), encoding="utf-8")
    (tmp / "old.jsonl").write_text(json.dumps(old) + "\n", encoding="utf-8")
    for args in (["report", str(tmp / "old.json"), "-o", str(tmp / "out")],
                 ["simulate", "-o", str(tmp / "sim.csv"), "--from", str(tmp / "old.json")],
                 ["merge", str(tmp / "old.jsonl")]):
        err = run(*args, status=2).stderr
        if str(tmp / "old.json") not in err or "schema_version" not in err or "write the result again" not in err:
            fail(f"rwcalc {args[0]} of a version-1 result: {err.strip()}")
    (tmp / "rad.json").write_text(json.dumps(rad), encoding="utf-8")
    for args in (["report", str(tmp / "rad.json"), "-o", str(tmp / "out2")],
                 ["simulate", "-o", str(tmp / "sim2.csv"), "--from", str(tmp / "rad.json")]):
        err = run(*args, status=2).stderr
        if "\"units.rate\" is \"rad/s\"" not in err or "without --output-unit" not in err:
            fail(f"rwcalc {args[0]} of an analysis in rad/s: {err.strip()}")

    if failures:
        sys.exit(f"{len(failures)} failure(s)")
    print(f"{len(docs) + len(lines)} documents valid against docs/result.schema.json")


main()
