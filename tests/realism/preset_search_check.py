#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks tools/research/preset_search.py (docs/decisions/frozen-snow-and-gravel-trade-off.md): the
same --rng-seed writes the same variant, only the drawn keys change and each value lies in its
range, a SURFACE/ parameter changes that second preset, the verdict line (with --distance) has its
documented shape and counts gravel among the misses exactly when a held-out gravel source put it
in another category, a cache holding the unseen sources is searched without them, bad parameters
are refused with a message, and --check lists the googletest tests a variant fails (a level far
from the calibration fails GranularSurfaces.CalibratedToAboutMinus12DbfsPeak of TEST_ENGINE, the
shipped level does not; a filter matching no test is refused). Needs the recordings cache (exits
77, skipped, without it).

    preset_search_check.py SOURCE_DIR UNDERFOOT_BINARY SCRATCH_DIR TEST_ENGINE
"""
import filecmp
import os
import re
import shutil
import subprocess
import sys


def fail(message):
    print(f"FAIL: {message}")
    sys.exit(1)


def main():
    source, binary, scratch, test_engine = sys.argv[1:5]
    cache = os.environ.get("UNDERFOOT_RECORDINGS") or os.path.join(source, "build", "recordings")
    if not os.path.isfile(os.path.join(cache, "manifest.csv")):
        print(f"SKIP: no recordings cache at {cache} (bash scripts/fetch-recordings.sh)")
        sys.exit(77)
    tool = os.path.join(source, "tools", "research", "preset_search.py")
    base = os.path.join(source, "engine", "data", "surfaces")
    shutil.rmtree(scratch, ignore_errors=True)
    params = ["2:gain_db:-26:-8", "0:gain_db:-16:-15", "1:q_min:2:12:log"]

    def search(out, *extra, only=1):
        return subprocess.run(
            [sys.executable, tool, "--surface", "gravel", "--variants", str(only + 1), "--only",
             str(only), "--rng-seed", "11", "--seeds", "7", "--sources", "minetest,ufoai",
             "--recordings", cache, "--base", base, "--out", out, "--underfoot", binary, *extra],
            capture_output=True, text=True)

    runs = []
    for name in ("a", "b"):
        r = search(os.path.join(scratch, name), "--distance", *params)
        if r.returncode != 0:
            fail(f"preset_search.py exited {r.returncode}: {r.stderr}{r.stdout}")
        runs.append(r.stdout.strip().splitlines())
    for lines in runs:
        if len(lines) != 1:
            fail(f"expected one line (--only 1), got {lines}")
    a = os.path.join(scratch, "a", "gravel_11_1")
    b = os.path.join(scratch, "b", "gravel_11_1")
    line = runs[0][0]
    m = re.match(r"^\s*(\d+) placed distance [0-9.]+ nearest-other \w+ [0-9.]+ "
                 r"(?:closest|NOT-closest) flatness (-?[0-9.]+) dB all: category (\d+) "
                 r"material (\d+) missed (\d+) \(([^)]*)\) (\S+) (.*) \| s7:(\S+)$", line)
    if not m:
        fail(f"verdict line not in its documented shape: {line}")
    if int(m.group(1)) > 2:
        fail(f"{m.group(1)} placed, but two held-out sources at one seed count: {line}")
    if not -60.0 < float(m.group(2)) < 0.0:
        fail(f"flatness {m.group(2)} dB is not a spectral flatness: {line}")
    per_surface = [re.fullmatch(r"(\w+):(\d+)", x) for x in m.group(6).split()]
    if not all(per_surface) or sum(int(x.group(2)) for x in per_surface) != int(m.group(5)):
        fail(f"the misses per surface must be SURFACE:COUNT adding up to the total: {line}")
    # minetest and UFO:AI are gravel's only sources: one seed, one cache, so gravel is a miss
    # (once) exactly when fewer than both placed it.
    gravel_missed = {x.group(1): int(x.group(2)) for x in per_surface}.get("gravel", 0)
    if gravel_missed != (1 if int(m.group(1)) < 2 else 0):
        fail(f"{m.group(1)} of 2 gravel sources placed it, but gravel is missed "
             f"{gravel_missed} times: {line}")
    if m.group(7) != a:
        fail(f"the line names {m.group(7)}, the variant is {a}")
    if runs[0][0].replace(a, "VARIANT") != runs[1][0].replace(b, "VARIANT"):
        fail(f"the same --rng-seed gave other values:\n{runs[0][0]}\n{runs[1][0]}")
    # Two caches (the same one twice): the sums are per cache too, and the two halves agree.
    r = subprocess.run(
        [sys.executable, tool, "--surface", "gravel", "--variants", "2", "--only", "1",
         "--rng-seed", "11", "--seeds", "7", "--recordings", f"{cache},{cache}", "--base", base,
         "--out", os.path.join(scratch, "c"), "--underfoot", binary, *params],
        capture_output=True, text=True)
    two = re.search(r"all: category (\d+) material (\d+) \(per cache (\d+)/(\d+) (\d+)/(\d+)\)",
                    r.stdout)
    if r.returncode != 0 or not two:
        fail(f"two caches: expected the sums per cache, got {r.returncode}: {r.stderr}{r.stdout}")
    cat, mat, c1, m1, c2, m2 = (int(g) for g in two.groups())
    if (c1, m1) != (c2, m2) or (cat, mat) != (c1 + c2, m1 + m2) or (c1, m1) != (
            int(m.group(3)), int(m.group(4))):
        fail(f"two copies of one cache must give equal halves summing to the total, each equal "
             f"to the one-cache line: {r.stdout}")
    # A cache holding the unseen sources is searched without them: rows of sources 0ad and
    # berusky2 whose files do not exist change nothing, and the search says it left them out.
    unseen = os.path.join(scratch, "unseen_cache")
    os.makedirs(unseen)
    for entry in os.listdir(cache):
        if entry != "manifest.csv":
            os.symlink(os.path.abspath(os.path.join(cache, entry)), os.path.join(unseen, entry))
    with open(os.path.join(cache, "manifest.csv")) as f:
        rows = f.read().rstrip("\n")
    with open(os.path.join(unseen, "manifest.csv"), "w") as f:
        f.write(rows + "\n0ad/gravel/missing.ogg,0ad,0ad-data,0,CC-BY-SA-3.0,gravel,nobody\n"
                "berusky2/snow/missing.wav,berusky2,berusky2-data,0,GPL-2+,snow,nobody\n")
    u = os.path.join(scratch, "u")
    r = subprocess.run(
        [sys.executable, tool, "--surface", "gravel", "--variants", "2", "--only", "1",
         "--rng-seed", "11", "--seeds", "7", "--sources", "minetest,ufoai", "--recordings",
         unseen, "--base", base, "--out", u, "--underfoot", binary, "--distance", *params],
        capture_output=True, text=True)
    if (r.returncode != 0
            or "leaving out the unseen sources (0ad, berusky2: 2 files)" not in r.stderr):
        fail(f"a cache with the unseen sources: expected them left out, saying so; got "
             f"{r.returncode}: {r.stderr}{r.stdout}")
    if r.stdout.strip().replace(os.path.join(u, "gravel_11_1"), "VARIANT").replace(
            os.path.join(u, "recordings_0"), "CACHE") != runs[0][0].replace(a, "VARIANT"):
        fail(f"without its unseen sources the cache must give the same line:\n{r.stdout}\n"
             f"{runs[0][0]}")
    cmp = filecmp.dircmp(a, b)
    if cmp.diff_files or cmp.left_only or cmp.right_only:
        fail(f"the same --rng-seed wrote different variants: {cmp.diff_files}")
    with open(os.path.join(base, "gravel.toml")) as f:
        shipped = f.read().split("\n")
    with open(os.path.join(a, "gravel.toml")) as f:
        variant = f.read().split("\n")
    if len(shipped) != len(variant):
        fail("a drawn key that exists must be replaced in place, not added")
    changed = [(s, v) for s, v in zip(shipped, variant) if s != v]
    if len(changed) != 3:
        fail(f"expected the three drawn keys to change, got {changed}")
    ranges = {"gain_db": [(-26, -8), (-16, -15)], "q_min": [(2, 12)]}
    for s, v in changed:
        key, value = re.match(r"^\s*(\w+)\s*=\s*([-0-9.e]+)", v).groups()
        if not any(lo <= float(value) <= hi for lo, hi in ranges.get(key, [])):
            fail(f"{key} = {value} is outside its range ({v!r})")
        if "#" in s and "#" not in v:
            fail(f"the comment of {s!r} was lost")
    for f in os.listdir(base):
        if f != "gravel.toml" and not filecmp.cmp(os.path.join(base, f), os.path.join(a, f),
                                                  shallow=False):
            fail(f"{f} changed, only gravel.toml was searched")
    # A second preset searched together with the first: its key changes in its own file, the
    # line names it, and the first preset's keys are drawn as before (variant 0: the draws of
    # a later variant follow every parameter's draw of the ones before).
    one = search(os.path.join(scratch, "one"), *params, only=0)
    r = search(os.path.join(scratch, "two"), *params, "water/1:gain_db:-9:-8", only=0)
    one_dir = os.path.join(scratch, "one", "gravel_11_0")
    two_dir = os.path.join(scratch, "two", "gravel_11_0")
    if one.returncode != 0 or r.returncode != 0 or " water/1:gain_db=" not in r.stdout:
        fail(f"a SURFACE/ parameter: expected it in the line, got {r.returncode}: "
             f"{one.stderr}{r.stderr}{r.stdout}")
    if not filecmp.cmp(os.path.join(one_dir, "gravel.toml"), os.path.join(two_dir, "gravel.toml"),
                       shallow=False):
        fail("a SURFACE/ parameter changed the draws of --surface's own parameters")
    if filecmp.cmp(os.path.join(base, "water.toml"), os.path.join(two_dir, "water.toml"),
                   shallow=False):
        fail("a SURFACE/ parameter left its preset unchanged")
    for bad, expected in (("2:gain_db:-8:-26", "expected 0 < LOW < HIGH"),
                          ("nowhere/1:gain_db:1:2", "no such preset"),
                          ("x:gain_db:1:2", "LAYER must be an integer"),
                          ("9:gain_db:1:2", "no [[layer]] number 9")):
        r = search(os.path.join(scratch, "bad"), bad)
        if r.returncode == 0 or expected not in r.stderr + r.stdout:
            fail(f"parameter {bad}: expected a refusal with '{expected}', got "
                 f"{r.returncode}: {r.stderr}{r.stdout}")
    # --check: the calibration test fails for a gravel 45 dB too quiet, not for its own level
    # (gain_db -15.3), and the line lists it with the cache's index; a bad --check is refused.
    calibration = "GranularSurfaces.CalibratedToAboutMinus12DbfsPeak"
    check = f"{test_engine}:{calibration}"
    for level, expected in (("0:gain_db:-60.01:-60", f"checks failed 1 ({calibration}@0)"),
                            ("0:gain_db:-15.31:-15.3", "checks failed 0 ()")):
        r = search(os.path.join(scratch, "check"), "--check", check, level)
        if r.returncode != 0 or f") {expected} " not in r.stdout:
            fail(f"--check with {level}: expected '{expected}' after the misses, got "
                 f"{r.returncode}: {r.stderr}{r.stdout}")
    r = search(os.path.join(scratch, "check"), "--check", test_engine, "0:gain_db:-16:-15")
    if r.returncode == 0 or "expected PROGRAM:FILTER" not in r.stderr:
        fail(f"--check without a filter: expected a refusal, got {r.returncode}: {r.stderr}")
    r = search(os.path.join(scratch, "check"), "--check", f"{test_engine}:NoSuchSuite.*",
               "0:gain_db:-16:-15")
    if r.returncode == 0 or "matches no test" not in r.stderr:
        fail(f"--check whose filter matches no test: expected a refusal (a check that runs "
             f"nothing cannot fail), got {r.returncode}: {r.stderr}{r.stdout}")
    shutil.rmtree(scratch, ignore_errors=True)
    print("ok: same seed, same variant; only the drawn keys change, in range; a second preset "
          "searched alongside; the misses add up; the unseen sources left out; bad parameters "
          "refused; --check lists the tests a variant fails")


if __name__ == "__main__":
    main()
