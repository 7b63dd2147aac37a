#!/usr/bin/env python3
"""Golden outputs compared as data, not as bytes.

rwcalc's floating results differ in their last digits between processors: glibc chooses the
implementation of its mathematical functions by processor (FMA or not), and long-double
arithmetic runs on the x87 unit, whose transcendental instructions round differently on AMD and
Intel processors. So a recorded output is compared as numbers:

- strings and integers exactly (a count, a noise type α, a class, a named effect must not move);
- floating numbers within a relative tolerance, 1e-9 by default. The machine-to-machine
  differences seen are below 1e-11 relative (an EDF of 378.7285420604458 against
  378.72854206092734); a genuine change of a result moves it by far more than 1e-9.
- a likelihood-ratio `statistic` (a difference of two large −2 ln L) within 1e-6 absolute and its
  `p_value` within 1e-6 relative; an `iterations` count within 3 or 10 %;
- a number printed rounded (text tables, CSV, notes) may also differ by one unit in its last
  printed digit: two machines can round a value that sits on a rounding boundary differently.

JSON is parsed whole (or line by line for JSON Lines); text and CSV are cut into numbers and the
text between them, which must match exactly. Outputs that carry no floating result (the pulse
records of `simulate`) are compared by SHA-256 in SHA256SUMS, byte for byte.

A JSON array longer than THIN_LENGTH is recorded thinned: THIN_KEEP evenly spaced elements in
full, its length, and a SHA-256 of the discrete values (strings with their decimals masked,
integers, booleans) of every element, so that a flipped α anywhere in a 10^6-point `--tau all`
output is still seen while the recorded file stays small.

Usage:
  compare.py check RECORDED_DIR NEW_DIR [--rel R]   compare NEW_DIR's *.out with the record
  compare.py record NEW_DIR RECORDED_DIR            record NEW_DIR's outputs (thinned, gzipped;
                                                    those named in NEW_DIR/BYTE_IDENTICAL by SHA-256)
  compare.py perturb REL RECORDED_DIR OUT_DIR [--one]
        copy the record with every floating number (or, with --one, the first floating number of
        the first JSON output) multiplied by 1 + REL: the check must pass at 1e-12 and fail at 1e-6.
  --discrete  compare only what must not move with the last digits of a floating result: strings
              (decimals masked) and integers; the input's own size and SHA-256 are not compared
              (tests/golden/perturbed.sh moves the inputs' last digits on purpose).
Exit status: 0 same, 1 a difference (the first one of each output is printed), 2 usage.
"""
import gzip
import hashlib
import json
import math
import os
import re
import sys

THIN_LENGTH = 2000
THIN_KEEP = 400
THINNED = "__thinned_array__"
BYTE_SUMS = "SHA256SUMS"
# A number as rwcalc prints it: sign, digits, optional fraction, optional exponent. Letters or an
# underscore right before it belong to a name (gl2d_0C, tau0), which is text.
BLANKS = re.compile(r" +")
NUMBER = re.compile(r"(?<![A-Za-z_0-9.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


class Difference(Exception):
    pass


# --discrete: floating numbers are not compared, nor what describes the input file itself.
DISCRETE = False
INPUT_FILE_KEYS = {"file_bytes", "sha256"}
INPUT_FILE_TEXT = re.compile(r"\d+ bytes, SHA-256 [0-9a-f]{64}")


# ---- numbers ------------------------------------------------------------------------------------
def last_digit_unit(token):
    """The value of one unit in the last printed digit of a decimal token, or 0 for an integer."""
    mantissa, _, exponent = token.lower().partition("e")
    if "." not in mantissa:
        return 0.0
    decimals = len(mantissa.split(".")[1])
    return 10.0 ** (int(exponent or 0) - decimals)


def significant_digits(token):
    mantissa = token.lower().partition("e")[0].lstrip("+-").replace(".", "").lstrip("0")
    return len(mantissa)


def numbers_agree(want, got, rel):
    """Tokens of two numbers: integers exactly, decimals within rel or one unit of a rounded print."""
    is_int = lambda t: re.fullmatch(r"[-+]?\d+", t) is not None
    if is_int(want) and is_int(got):
        return int(want) == int(got)
    if DISCRETE:
        return True
    a, b = float(want), float(got)
    if a == b or abs(a - b) <= rel * max(abs(a), abs(b)):
        return True
    # A value printed with fewer digits than a double holds was rounded: allow its last digit.
    if min(significant_digits(want), significant_digits(got)) < 15:
        unit = max(last_digit_unit(want), last_digit_unit(got))
        return abs(a - b) <= unit * (1 + 1e-9)
    return False


def text_agrees(want, got, rel):
    """Two lines of text: the same words and punctuation, the numbers within tolerance."""
    if DISCRETE:
        want, got = INPUT_FILE_TEXT.sub("(input)", want), INPUT_FILE_TEXT.sub("(input)", got)
    # Columns are padded to the printed width of their numbers: runs of blanks compare as one.
    if BLANKS.sub(" ", NUMBER.sub("#", want)) != BLANKS.sub(" ", NUMBER.sub("#", got)):
        return False
    return all(numbers_agree(a, b, rel) for a, b in zip(NUMBER.findall(want), NUMBER.findall(got)))


# How many iterations a minimiser or a root search took moves with the last digits of its input, as
# a floating result does (a processor's rounding, a perturbed input): compared within 3 or 10 %, and
# not at all by --discrete.
ITERATION_KEYS = {"iterations"}


def iterations_agree(want, got, path):
    if DISCRETE:
        return
    if not isinstance(want, int) or not isinstance(got, int) or abs(want - got) > max(3, 0.1 * abs(want)):
        raise Difference(f"{path}: recorded {want!r} iterations, got {got!r}")


# A likelihood-ratio statistic is the difference of two −2 ln L of the whole record (10^4–10^6 each,
# so its last bits are those of the terms): another processor's rounding moves a statistic of 0.35
# by 4e-10 (1e-9 of it). Compared to 1e-6 absolute, and its p-value to 1e-6 relative; the decisions
# they lead to (fired, named) are compared exactly.
STATISTIC_ABS = 1e-6
P_VALUE_REL = 1e-6
LIKELIHOOD_RATIO_KEYS = {"statistic", "p_value"}


def likelihood_ratio_agrees(key, want, got, rel, path):
    if DISCRETE or not isinstance(want, float) or not isinstance(got, (int, float)):
        return compare_json(want, got, rel, path)
    if key == "statistic" and abs(want - got) <= STATISTIC_ABS:
        return
    if not float_agrees(want, float(got), max(rel, P_VALUE_REL) if key == "p_value" else rel):
        raise Difference(f"{path}: recorded {want!r}, got {got!r}")


def float_agrees(a, b, rel):
    if DISCRETE or a == b or (math.isnan(a) and math.isnan(b)):
        return True
    return abs(a - b) <= rel * max(abs(a), abs(b))


# ---- JSON ---------------------------------------------------------------------------------------
def discrete_digest(value):
    """SHA-256 of the values that must match exactly: integers, booleans, strings (decimals masked)."""
    h = hashlib.sha256()

    def walk(v):
        if isinstance(v, dict):
            for k in sorted(v):
                h.update(k.encode() + b":")
                walk(v[k])
        elif isinstance(v, list):
            h.update(b"[%d]" % len(v))
            for x in v:
                walk(x)
        elif isinstance(v, bool) or isinstance(v, int):
            h.update(repr(v).encode() + b";")
        elif isinstance(v, str):
            h.update(re.sub(r"\d*\.\d+(?:[eE][-+]?\d+)?|\d+[eE][-+]?\d+", "#", v).encode() + b";")
        elif v is None:
            h.update(b"null;")
        else:
            h.update(b"f;")
    walk(value)
    return h.hexdigest()


def thin(value):
    """The value with every array longer than THIN_LENGTH replaced by its thinned record."""
    if isinstance(value, dict):
        return {k: thin(v) for k, v in value.items()}
    if not isinstance(value, list):
        return value
    if len(value) <= THIN_LENGTH:
        return [thin(v) for v in value]
    n = len(value)
    kept = sorted({round(i * (n - 1) / (THIN_KEEP - 1)) for i in range(THIN_KEEP)})
    return {THINNED: {"length": n, "discrete_sha256": discrete_digest(value),
                      "kept": {str(i): thin(value[i]) for i in kept}}}


def compare_json(want, got, rel, path="$"):
    if isinstance(want, dict) and THINNED in want:
        rec = want[THINNED]
        if isinstance(got, dict) and THINNED in got:   # two records compared with each other
            got = got[THINNED]
            if (got["length"], got["discrete_sha256"]) != (rec["length"], rec["discrete_sha256"]):
                raise Difference(f"{path}: thinned arrays differ in length or discrete values")
            return compare_json(rec["kept"], got["kept"], rel, path)
        if not isinstance(got, list) or len(got) != rec["length"]:
            raise Difference(f"{path}: array of {rec['length']} elements recorded, got "
                             f"{len(got) if isinstance(got, list) else type(got).__name__}")
        for i, elem in rec["kept"].items():
            compare_json(elem, got[int(i)], rel, f"{path}[{i}]")
        if discrete_digest(got) != rec["discrete_sha256"]:
            raise Difference(f"{path}: an integer or string differs in an element that is not kept "
                             f"in the record (discrete SHA-256 {rec['discrete_sha256'][:12]}… against "
                             f"{discrete_digest(got)[:12]}…)")
        return
    if isinstance(want, dict):
        if not isinstance(got, dict) or sorted(want) != sorted(got):
            extra = sorted(set(got) - set(want)) if isinstance(got, dict) else type(got).__name__
            missing = sorted(set(want) - set(got)) if isinstance(got, dict) else ""
            raise Difference(f"{path}: keys differ (missing {missing}, new {extra})")
        for k in want:
            if k in ITERATION_KEYS:
                iterations_agree(want[k], got[k], f"{path}.{k}")
            elif k in LIKELIHOOD_RATIO_KEYS:
                likelihood_ratio_agrees(k, want[k], got[k], rel, f"{path}.{k}")
            elif not (DISCRETE and k in INPUT_FILE_KEYS):
                compare_json(want[k], got[k], rel, f"{path}.{k}")
    elif isinstance(want, list):
        if not isinstance(got, list) or len(want) != len(got):
            raise Difference(f"{path}: {len(want)} elements recorded, got "
                             f"{len(got) if isinstance(got, list) else type(got).__name__}")
        for i, (a, b) in enumerate(zip(want, got)):
            compare_json(a, b, rel, f"{path}[{i}]")
    elif isinstance(want, float) and isinstance(got, (int, float)) and not isinstance(got, bool):
        if not float_agrees(want, float(got), rel):
            raise Difference(f"{path}: recorded {want!r}, got {got!r}")
    elif isinstance(want, str) and isinstance(got, str):
        if not text_agrees(want, got, rel):
            raise Difference(f"{path}: recorded {want!r}, got {got!r}")
    elif type(want) is not type(got) or want != got:
        raise Difference(f"{path}: recorded {want!r}, got {got!r}")


# ---- files --------------------------------------------------------------------------------------
def parse(text):
    """('json', value), ('jsonl', [values]) or ('text', lines)."""
    try:
        return "json", json.loads(text)
    except ValueError:
        pass
    lines = text.splitlines()
    try:
        if lines and all(l.startswith("{") for l in lines):
            return "jsonl", [json.loads(l) for l in lines]
    except ValueError:
        pass
    return "text", lines


def compare_outputs(want_text, got_text, rel):
    kind, want = parse(want_text)
    got_kind, got = parse(got_text)
    if kind != got_kind:
        raise Difference(f"recorded as {kind}, got {got_kind}")
    if kind == "json":
        return compare_json(want, got, rel)
    if kind == "jsonl":
        if len(want) != len(got):
            raise Difference(f"{len(want)} lines recorded, got {len(got)}")
        for i, (a, b) in enumerate(zip(want, got), 1):
            compare_json(a, b, rel, f"line {i}: $")
        return
    if len(want) != len(got):
        raise Difference(f"{len(want)} lines recorded, got {len(got)}")
    for i, (a, b) in enumerate(zip(want, got), 1):
        if not text_agrees(a, b, rel):
            raise Difference(f"line {i}: recorded {a!r}, got {b!r}")


def read_recorded(path):
    with gzip.open(path, "rt", encoding="utf-8") as f:
        return f.read()


def reference_form(text):
    """What is recorded of an output: JSON thinned, anything else as it is."""
    kind, value = parse(text)
    if kind == "json":
        return json.dumps(thin(value), ensure_ascii=False, indent=0) + "\n"
    return text


def sha256_of(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def byte_sums(recorded):
    path = os.path.join(recorded, BYTE_SUMS)
    if not os.path.exists(path):
        return {}
    with open(path) as f:
        return {name: digest for digest, name in (l.split() for l in f if l.strip())}


def produced(new):
    """NEW_DIR's outputs: name -> path of the plain output, or of a recorded (.gz) one."""
    names = {f: os.path.join(new, f) for f in os.listdir(new) if f.endswith(".out")}
    names.update({f[:-3]: os.path.join(new, f) for f in os.listdir(new) if f.endswith(".out.gz")})
    names.update({n: None for n in byte_sums(new) if n not in names})
    return names


def compare_one(name, path, recorded, sums, new_sums, rel):
    if name in sums:
        digest = sha256_of(path) if path else new_sums.get(name)
        if digest != sums[name]:
            raise Difference("bytes differ (an output without floating results: compared byte for byte)")
        return
    if not os.path.exists(os.path.join(recorded, name + ".gz")) or path is None:
        raise Difference("no recorded output")
    if path.endswith(".gz"):
        got = read_recorded(path)
    else:
        with open(path, encoding="utf-8") as f:
            got = f.read()
    compare_outputs(read_recorded(os.path.join(recorded, name + ".gz")), got, rel)


def check(recorded, new, rel):
    sums, new_sums = byte_sums(recorded), byte_sums(new)
    outputs = produced(new)
    recorded_names = set(sums) | {f[:-3] for f in os.listdir(recorded) if f.endswith(".out.gz")}
    failures = 0
    for name in sorted(outputs):
        try:
            compare_one(name, outputs[name], recorded, sums, new_sums, rel)
        except Difference as d:
            print(f"output changed: {name}: {d}")
            failures += 1
    skipped = set()
    if os.path.exists(os.path.join(new, "SKIPPED")):
        with open(os.path.join(new, "SKIPPED")) as f:
            skipped = {l.split()[0] + ".out" for l in f if l.strip()}
    for name in sorted(recorded_names - set(outputs) - skipped):
        print(f"recorded but not produced: {name}")
        failures += 1
    if failures == 0:
        how = "integers and strings" if DISCRETE else f"floating numbers within {rel:g} relative"
        print(f"golden outputs: {len(outputs)} agree ({how})")
    return 1 if failures else 0


def record(new, recorded):
    byte_names = set()
    if os.path.exists(os.path.join(new, "BYTE_IDENTICAL")):
        with open(os.path.join(new, "BYTE_IDENTICAL")) as f:
            byte_names = {l.strip() for l in f if l.strip()}
    os.makedirs(recorded, exist_ok=True)
    for f in os.listdir(recorded):
        if f.endswith(".out.gz") or f == BYTE_SUMS:
            os.remove(os.path.join(recorded, f))
    sums = []
    for name in sorted(f for f in os.listdir(new) if f.endswith(".out")):
        src = os.path.join(new, name)
        if name in byte_names:
            sums.append(f"{sha256_of(src)}  {name}\n")
            continue
        with open(src, encoding="utf-8") as f:
            text = reference_form(f.read())
        with open(os.path.join(recorded, name + ".gz"), "wb") as raw:
            with gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as g:
                g.write(text.encode("utf-8"))
    with open(os.path.join(recorded, BYTE_SUMS), "w") as f:
        f.writelines(sums)
    print(f"recorded {len(os.listdir(recorded)) - 1} outputs and {len(sums)} byte sums in {recorded}")
    return 0


# ---- perturbation, for the check's own test -------------------------------------------------------
def perturb_json(value, factor, budget):
    if isinstance(value, dict):
        return {k: perturb_json(v, factor, budget) for k, v in value.items()}
    if isinstance(value, list):
        return [perturb_json(v, factor, budget) for v in value]
    if isinstance(value, float) and value != 0 and budget[0] != 0:
        budget[0] -= 1
        return value * factor
    return value


def perturb_text(text, factor):
    def one(m):
        t = m.group(0)
        if re.fullmatch(r"[-+]?\d+", t) or float(t) == 0:
            return t
        return repr(float(t) * factor)
    return "\n".join(NUMBER.sub(one, line) for line in text.split("\n"))


def perturb(rel, recorded, out, only_one):
    os.makedirs(out, exist_ok=True)
    factor = 1.0 + rel
    budget = [1 if only_one else -1]
    for name in sorted(os.listdir(recorded)):
        src = os.path.join(recorded, name)
        if not name.endswith(".out.gz"):
            with open(src, "rb") as f, open(os.path.join(out, name), "wb") as g:
                g.write(f.read())
            continue
        text = read_recorded(src)
        kind, value = parse(text)
        if kind == "json":
            text = json.dumps(perturb_json(value, factor, budget), ensure_ascii=False, indent=0) + "\n"
        elif not only_one:
            text = perturb_text(text, factor)
        with gzip.open(os.path.join(out, name), "wt", encoding="utf-8") as g:
            g.write(text)
    return 0


def main(argv):
    global DISCRETE
    rel = 1e-9
    if "--discrete" in argv:
        argv.remove("--discrete")
        DISCRETE = True
    if "--rel" in argv:
        i = argv.index("--rel")
        rel = float(argv[i + 1])
        del argv[i:i + 2]
    if len(argv) == 3 and argv[0] == "check":
        return check(argv[1], argv[2], rel)
    if len(argv) == 3 and argv[0] == "record":
        return record(argv[1], argv[2])
    if len(argv) in (4, 5) and argv[0] == "perturb":
        return perturb(float(argv[1]), argv[2], argv[3], argv[4:] == ["--one"])
    print(__doc__.split("Usage:")[1], file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
