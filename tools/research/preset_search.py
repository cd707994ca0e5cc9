#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A seeded random search over one surface preset's parameters, judged by the nested listener of
`underfoot compare --listener` (docs/explanation/realism.md, "The listener"; the searches behind
docs/decisions/frozen-snow-and-gravel-trade-off.md).

    python3 tools/research/preset_search.py --surface frozen_snow --variants 24 --seeds 3,7,11 \\
        --rng-seed 5 --sources lugaru,minetest,ufoai --distance \\
        1:gain_db:-11:-5 1:freq_min_hz:800:1400:log 2:gain_db:-12:-4 ...

Each PARAM is [SURFACE/]LAYER:KEY:LOW:HIGH[:log]: LAYER is the 1-based [[layer]] of the preset
(0: the preset's top level) of --surface, or of SURFACE when given (two presets searched
together: the renders are centred as one source, so one preset moves the others' verdicts), KEY
a key already there or added; a value is drawn uniformly in [LOW, HIGH] (log-uniformly with
`log`), one draw per PARAM in the order given, written with 4 significant digits (--only N
evaluates variant N alone, with the same draws). Every variant is a copy of the presets folder
(--base, default engine/data/surfaces) under --out with the searched presets changed;
it is rendered at every --seeds seed against every --recordings cache (comma-separated; default
$UNDERFOOT_RECORDINGS or build/recordings) with UNDERFOOT_SURFACES_DIR set to it.

One line per variant: how many held-out listeners put the surface in its category (summed over
seeds and caches; with --sources only those held-out sources count, e.g. the ones that recorded
its material); with --distance the descriptor distance at seed 7 (first cache) to its own
material's recordings and to the nearest other material's (`compare -s SURFACE --real ...`, as
`compare --all` computes them: "closest" or "NOT-closest") and its spectral flatness there; row
"all" of the nested table (category and material right, summed, then per cache when there are
several); "missed": how many times (seeds and caches summed) a surface, any surface, was put
in another category by a held-out source that recorded its material, with the count per
surface; with --check PROGRAM:FILTER (repeatable), the googletest program run with that
--gtest_filter on the variant against every cache, and the tests that failed, as
`checks failed N (Suite.Test@K ...)` with K the cache's place in --recordings (how the
deep and frozen snow searches screened variants against the checks that had failed a candidate,
docs/decisions/deep-snow-crunch-as-noise.md); the folder, the values and every listener's verdict.
A cache that holds the unseen source (`fetch-recordings.sh --unseen`) is searched without it,
saying so: presets are never chosen on it (docs/decisions/unseen-source.md).
The search only proposes: a variant is kept after `compare --figures` on seeds it was not chosen
on (docs/decisions/frozen-snow-and-gravel-trade-off.md), and the same --rng-seed gives the same
variants.
"""
import argparse
import math
import os
import random
import re
import shutil
import subprocess
import sys

from listener_common import CATEGORY


UNSEEN_SOURCES = ("0ad", "berusky2")  # fetch-recordings.sh --unseen: never searched on


def source_of(row):
    """The source column of a manifest row (None for a row without one)."""
    cells = row.split(",")
    return cells[1] if len(cells) > 1 else None


def without_unseen(cache, out, k):
    """The cache as the search may see it: when its manifest lists an unseen source
    (docs/decisions/unseen-source.md), a view under `out` without them (the other sources'
    folders linked, the manifest without their rows), else the cache itself."""
    manifest = os.path.join(cache, "manifest.csv")
    try:
        with open(manifest) as f:
            lines = f.read().splitlines()
    except OSError as e:
        sys.exit(f"{manifest}: cannot read the recordings' manifest ({e.strerror}); "
                 "bash scripts/fetch-recordings.sh writes it")
    kept = [l for l in lines if source_of(l) not in UNSEEN_SOURCES]
    if len(kept) == len(lines):
        return cache
    view = os.path.join(out, f"recordings_{k}")
    shutil.rmtree(view, ignore_errors=True)
    os.makedirs(view)
    for entry in os.listdir(cache):
        if entry not in UNSEEN_SOURCES + ("manifest.csv",):
            os.symlink(os.path.abspath(os.path.join(cache, entry)), os.path.join(view, entry))
    with open(os.path.join(view, "manifest.csv"), "w") as f:
        f.write("\n".join(kept) + "\n")
    n = len(lines) - len(kept)
    names = ", ".join(u for u in UNSEEN_SOURCES if any(source_of(l) == u for l in lines))
    print(f"leaving out the unseen sources ({names}: {n} file{'' if n == 1 else 's'}) of "
          f"{cache}: presets are never chosen on them", file=sys.stderr)
    return view


def set_keys(path, changes):
    """Sets `key = value` lines of a preset: changes is [(layer, key, text)], layer 0 = top."""
    with open(path) as f:
        lines = f.read().split("\n")
    for layer, key, text in changes:
        starts = [i for i, l in enumerate(lines) if l.strip() == "[[layer]]"]
        if layer > len(starts):
            sys.exit(f"{path}: no [[layer]] number {layer} (it has {len(starts)})")
        begin = 0 if layer == 0 else starts[layer - 1] + 1
        end = len(lines)
        for i in range(begin, len(lines)):
            if lines[i].strip().startswith("["):
                end = i
                break
        pattern = re.compile(rf"^(\s*{re.escape(key)}\s*=\s*)[^#]*?(\s*#.*)?$")
        for i in range(begin, end):
            m = pattern.match(lines[i])
            if m:
                lines[i] = m.group(1) + text + (("  " + m.group(2).strip()) if m.group(2) else "")
                break
        else:
            lines.insert(end if layer else begin, f"{key} = {text}")
    with open(path, "w") as f:
        f.write("\n".join(lines))


def parse_param(spec):
    surface, _, spec = spec.rpartition("/")
    parts = spec.split(":")
    if len(parts) not in (4, 5) or (len(parts) == 5 and parts[4] != "log"):
        sys.exit(f"parameter '{spec}': expected LAYER:KEY:LOW:HIGH[:log]")
    try:
        layer, low, high = int(parts[0]), float(parts[2]), float(parts[3])
    except ValueError:
        sys.exit(f"parameter '{spec}': LAYER must be an integer, LOW and HIGH numbers")
    if not low < high or (len(parts) == 5 and low <= 0):
        sys.exit(f"parameter '{spec}': expected 0 < LOW < HIGH with log, LOW < HIGH without")
    return surface, layer, parts[1], low, high, len(parts) == 5


def verdicts(text, surface):
    """(source, material heard) per held-out source, and row all's category and material counts."""
    if "per surface" not in text:
        sys.exit("underfoot compare --listener printed no per-surface table:\n" + text[-2000:])
    rows = [l for l in text.split("per surface")[1].splitlines() if l.split()[:1] == [surface]]
    if not rows:
        sys.exit(f"underfoot compare --listener has no row for surface '{surface}'")
    heard = re.findall(r"(\w+):(\w+)", rows[0])
    m = re.search(r"^all\s+\S+\s+\S+\s+\S+ \(\d+ %\)\s+(\d+)/\d+ \(\d+ %\)\s+(\d+)/", text,
                  re.M)
    return heard, (int(m.group(1)), int(m.group(2))) if m else (0, 0)


def strict_misses(text):
    """The surfaces some held-out source that recorded their material puts in another category
    (the per-surface table's category column k/n with k < n)."""
    table = text.split("per surface")[1].split("\n\n")[0]
    missed = []
    for row in (line.split() for line in table.splitlines()):
        m = re.fullmatch(r"(\d+)/(\d+)", row[2]) if len(row) > 3 else None
        if m and int(m.group(1)) < int(m.group(2)):
            missed.append(row[0])
    return missed


def distances(a, folder, cache):
    """Distance of the surface (seed 7) to its own material's recordings and to each other
    material's, as `compare --all` computes them (dry: a preset with a room is compared with dry
    recordings here)."""
    materials = sorted({m for s in os.listdir(cache) if os.path.isdir(os.path.join(cache, s))
                        for m in os.listdir(os.path.join(cache, s))
                        if os.path.isdir(os.path.join(cache, s, m))})
    env = dict(os.environ, UNDERFOOT_SURFACES_DIR=folder, UNDERFOOT_RECORDINGS=cache)
    distance = re.compile(r"\): ([0-9.]+)\s*$", re.M)
    # Against its own material's recordings (the default of `compare -s`), which names them.
    out = subprocess.run([a.underfoot, "compare", "-s", a.surface, "--seed", "7"], env=env,
                         capture_output=True, text=True).stdout
    m, d = re.search(r"recordings \((\w+)\)", out), distance.search(out)
    own_material, own = (m.group(1), float(d.group(1))) if m and d else (None, None)
    f = re.search(r"^flatness\s+dB\s+(\S+)", out, re.M)
    flatness = float(f.group(1)) if f else math.nan
    others = {}
    for material in materials:
        if material == own_material:
            continue
        folders = [os.path.join(cache, s, material) for s in sorted(os.listdir(cache))
                   if os.path.isdir(os.path.join(cache, s, material))]
        out = subprocess.run([a.underfoot, "compare", "-s", a.surface, "--seed", "7", "--real"] +
                             folders, env=env, capture_output=True, text=True).stdout
        d = distance.search(out)
        if d:
            others[material] = float(d.group(1))
    return own, others, flatness


def failed_checks(checks, folder, caches):
    """The googletest tests of each PROGRAM:FILTER that fail with the variant's presets, against
    each cache (`Suite.Test@K`, K the cache's index), in the order run."""
    failed = []
    for program, test_filter in checks:
        for k, cache in enumerate(caches):
            env = dict(os.environ, UNDERFOOT_SURFACES_DIR=folder, UNDERFOOT_RECORDINGS=cache)
            out = subprocess.run([program, f"--gtest_filter={test_filter}"], env=env,
                                 capture_output=True, text=True).stdout
            names = re.findall(r"^\[  FAILED  \] (\S+\.\S+) \(", out, re.M)
            ran = re.search(r"^\[==========\] (\d+) tests? from \d+ test suites? ran", out, re.M)
            if not ran:
                sys.exit(f"{program} --gtest_filter={test_filter}: no googletest summary "
                         f"(UNDERFOOT_RECORDINGS={cache}):\n{out[-2000:]}")
            if int(ran.group(1)) == 0:
                sys.exit(f"{program} --gtest_filter={test_filter}: the filter matches no test")
            failed += [f"{n}@{k}" for n in names]
    return failed


def parse_check(spec):
    program, sep, test_filter = spec.partition(":")  # a filter may hold ':' itself
    if not sep or not program or not test_filter:
        sys.exit(f"--check '{spec}': expected PROGRAM:FILTER (a googletest program and a "
                 "--gtest_filter pattern)")
    if not (os.path.isfile(program) and os.access(program, os.X_OK)):
        sys.exit(f"--check '{spec}': {program} is not an executable file")
    return program, test_filter


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--surface", required=True)
    ap.add_argument("--variants", type=int, default=20)
    ap.add_argument("--seeds", default="7")
    ap.add_argument("--rng-seed", type=int, default=1)
    ap.add_argument("--sources", default="", help="held-out sources that count (default: all)")
    ap.add_argument("--recordings",
                    default=os.environ.get("UNDERFOOT_RECORDINGS", "build/recordings"))
    ap.add_argument("--base", default="engine/data/surfaces")
    ap.add_argument("--out", default="/tmp/preset_search")
    ap.add_argument("--underfoot", default="build/app/cli/underfoot")
    ap.add_argument("--category", default="", help="the surface's category (default: from its id)")
    ap.add_argument("--distance", action="store_true")
    ap.add_argument("--only", type=int, action="append", default=[],
                    help="evaluate only variant N (repeatable): the same draws, the others skipped")
    ap.add_argument("--check", action="append", default=[], metavar="PROGRAM:FILTER",
                    help="also run this googletest program with this filter on each variant, "
                         "against each cache, and list the tests that fail (repeatable)")
    ap.add_argument("params", nargs="+", metavar="PARAM")
    a = ap.parse_args()
    params = [parse_param(p) for p in a.params]
    checks = [parse_check(c) for c in a.check]
    seeds = [int(s) for s in a.seeds.split(",")]
    caches = [without_unseen(c, a.out, k) for k, c in enumerate(a.recordings.split(","))]
    counted = set(filter(None, a.sources.split(",")))
    preset = os.path.join(a.base, a.surface + ".toml")
    if not os.path.isfile(preset):
        sys.exit(f"{preset}: no such preset (--base is the presets folder)")
    for surface in sorted({p[0] for p in params if p[0]}):
        if not os.path.isfile(os.path.join(a.base, surface + ".toml")):
            sys.exit(f"{os.path.join(a.base, surface + '.toml')}: no such preset (a PARAM's "
                     "SURFACE/ names a preset of --base)")
    category = a.category
    if not category:
        m = re.search(r"^category\s*=\s*['\"](\w+)['\"]", open(preset).read(), re.M)
        category = m.group(1) if m else "aggregate"
    wanted = {m for m, c in CATEGORY.items() if c == category}
    if not wanted:
        sys.exit(f"{preset}: category '{category}' has no recorded material")
    rng = random.Random(a.rng_seed)
    for n in range(a.variants):
        changes = []
        for surface, layer, key, low, high, log in params:
            if log:
                v = math.exp(rng.uniform(math.log(low), math.log(high)))
            else:
                v = rng.uniform(low, high)
            changes.append((surface or a.surface, layer, key, f"{v:.4g}"))
        if a.only and n not in a.only:
            continue
        folder = os.path.join(a.out, f"{a.surface}_{a.rng_seed}_{n}")
        shutil.rmtree(folder, ignore_errors=True)
        shutil.copytree(a.base, folder)
        for surface in sorted({c[0] for c in changes}):
            set_keys(os.path.join(folder, surface + ".toml"),
                     [c[1:] for c in changes if c[0] == surface])
        runs = []
        for seed in seeds:
            for k, cache in enumerate(caches):
                env = dict(os.environ, UNDERFOOT_SURFACES_DIR=folder, UNDERFOOT_RECORDINGS=cache)
                runs.append((seed, k, subprocess.Popen(
                    [a.underfoot, "compare", "--listener", "--seed", str(seed)], env=env,
                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)))
        placed, said, missed = 0, [], {}
        right = [[0, 0] for _ in caches]  # category, material per cache
        for seed, k, p in runs:
            text = p.communicate()[0]
            heard, (cat, mat) = verdicts(text, a.surface)
            for s in strict_misses(text):
                missed[s] = missed.get(s, 0) + 1
            right[k][0] += cat
            right[k][1] += mat
            placed += sum(1 for s, m in heard if m in wanted and (not counted or s in counted))
            said.append(f"s{seed}:" + ",".join(f"{s}:{m}" for s, m in heard))
        distance = ""
        if a.distance:
            own, rivals, flatness = distances(a, folder, caches[0])
            if own is None:
                distance = " distance ?"
            else:
                near = min(rivals.items(), key=lambda kv: kv[1]) if rivals else ("-", math.inf)
                distance = (f" distance {own:.2f} nearest-other {near[0]} {near[1]:.2f} "
                            f"{'closest' if own < near[1] else 'NOT-closest'} "
                            f"flatness {flatness:.1f} dB")
        values = " ".join(f"{'' if s == a.surface else s + '/'}{l}:{k}={t}"
                          for s, l, k, t in changes)
        category_right = sum(c for c, _ in right)
        material_right = sum(m for _, m in right)
        per_cache = (" (per cache " + " ".join(f"{c}/{m}" for c, m in right) + ")"
                     if len(caches) > 1 else "")
        misses = " ".join(f"{s}:{k}" for s, k in sorted(missed.items()))
        checked = ""
        if checks:
            failed = failed_checks(checks, folder, caches)
            checked = f" checks failed {len(failed)} ({' '.join(failed)})"
        print(f"{placed:3d} placed{distance} all: category {category_right} material "
              f"{material_right}{per_cache} missed {sum(missed.values())} ({misses}){checked} "
              f"{folder} {values} | {' '.join(said)}", flush=True)


if __name__ == "__main__":
    main()
