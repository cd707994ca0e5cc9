#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Instructions per 64-frame block of the shipped scenes, counted by callgrind.

The timed scene benchmark (`underfoot bench --only scenes`) moves by about +-0.3 in worst /
median between runs on a shared machine; instruction counts do not move. This script runs
`underfoot bench --only scene-instructions` under callgrind, one valgrind process per scene
(--jobs at a time). That mode runs each scene once on the timed benchmark's input and seed and
dumps callgrind's counts after every 64-frame block with the label "<scene> <block>" (a dump
zeroes the counts; client requests in app/cli/cmd_bench.cpp), so each dump's total is one
block's instructions (plus the loop's few, the same for every block). The script reads the dumps
and prints, per scene: median, p99 and worst instructions per block, p99 / median,
worst / median and the worst block (its index and start time); for the scenes with a room, the
same figures for the reverb's own instructions per block (`Convolver::process`, inclusive), so
that what the reverb adds to a block is seen apart from the surfaces' strikes and grains; then,
per scene, what the worst block spends its instructions on beside a median block (inclusive and
self instructions per function, from callgrind's call graph).

    python3 tools/perf/scene_block_instructions.py             # every shipped scene, --seconds 5
    python3 tools/perf/scene_block_instructions.py --scene wood_reverb --seconds 1 --top 12

It prints each valgrind command it runs (stderr), e.g.

    valgrind --tool=callgrind --combine-dumps=yes --instr-atstart=no
        --callgrind-out-file=DIR/wood_reverb.callgrind build/app/cli/underfoot-nodebug-PID
        bench --only scene-instructions --seconds 5 --scene wood_reverb

where underfoot-nodebug-PID is build/app/cli/underfoot without its debug sections, beside it so
that it reads the source tree's data (see program_copy), removed afterwards.
The counts depend on the binary (compiler, flags) and, by a few instructions in glibc's memcpy,
on where the heap's buffers fall (the program's path changes that). Instructions are not time:
a division, a cache miss or a denormal costs one instruction and many cycles. valgrind runs
the AVX paths (it does not emulate AVX-512). Python standard library only.
"""
import argparse
import mmap
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VALGRIND_OPTIONS = [
    "--tool=callgrind",
    "--combine-dumps=yes",  # one file per scene, one part per block
    "--instr-atstart=no",  # the mode switches instrumentation on once the scene is built
]


# --- reading callgrind's output ------------------------------------------------------------


_PART_LINE = re.compile(rb"^(?:(part:)[^\n]*"
                        rb"|desc: Trigger: Client Request: ([^\n]*)"
                        rb"|(totals|summary):[ \t]*(\d+)[^\n]*)$", re.M)


def read_parts(path):
    """The parts of a callgrind output file (one per dump) as a list of
    (label, total instructions, byte offset of the part's first line).

    `label` is the string of CALLGRIND_DUMP_STATS_AT (None for dumps of another trigger, e.g.
    the one at program termination). The total is the part's "totals:" line (the sum of its
    costs; if absent, its "summary:"). Only the first event (Ir) is read."""
    parts = []
    label, total, start = None, None, None
    with open(path, "rb") as f:
        if os.fstat(f.fileno()).st_size == 0:
            return parts
        with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as data:
            for m in _PART_LINE.finditer(data):
                if m.group(1):
                    if start is not None:
                        parts.append((label, total, start))
                    label, total, start = None, None, m.start()
                    continue
                if start is None:
                    start = 0  # a file without "part:" lines: one part from the top
                if m.group(2) is not None:
                    label = m.group(2).decode("utf-8", "replace").strip()
                elif m.group(3) == b"totals" or total is None:
                    total = int(m.group(4))
    if start is not None:
        parts.append((label, total, start))
    return parts


_NAME_DEF = re.compile(rb"^(c?fn|c?ob|fl|fi|fe|cfi|cfl)=\((\d+)\) ([^\n]*)$", re.M)
_TABLE = {b"fn": "fn", b"cfn": "fn", b"ob": "ob", b"cob": "ob", b"fl": "fl", b"fi": "fl",
          b"fe": "fl", b"cfi": "fl", b"cfl": "fl"}


def read_names(path):
    """callgrind's compressed names of a whole file: "fn=(12) name" defines function 12 once per
    file, later lines say "fn=(12)". Returns {"fn": {id: name}, "ob": ..., "fl": ...}."""
    names = {"fn": {}, "ob": {}, "fl": {}}
    with open(path, "rb") as f:
        if os.fstat(f.fileno()).st_size == 0:
            return names
        with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as data:
            for m in _NAME_DEF.finditer(data):
                names[_TABLE[m.group(1)]][m.group(2).decode()] = m.group(3).decode(
                    "utf-8", "replace").strip()
    return names


def _function_name(names, value):
    value = value.strip()
    if value.startswith("("):
        close = value.find(")")
        key = value[1:close]
        rest = value[close + 1:].strip()
        return rest or names["fn"].get(key, "(" + key + ")")
    return value


def read_functions(path, offset, names=None):
    """Self and inclusive instructions per function of the one part starting at `offset`.

    Returns {function: [self, inclusive]}. Inclusive = self + the costs of the calls it makes
    (callgrind writes each call's inclusive cost on the line after "calls="; a recursive call
    would count twice). `names`: read_names(path) (read here when None)."""
    if names is None:
        names = read_names(path)
    npos = 1
    funcs = {}
    current = None
    after_calls = False
    with open(path, "rb") as f:
        f.seek(offset)
        first = True
        for raw in f:
            line = raw.decode("utf-8", "replace").rstrip("\n")
            if line.startswith("part:") and not first:
                break
            first = False
            if not line or line.startswith("#"):
                continue
            if line.startswith("positions:"):
                npos = len(line.split(":", 1)[1].split())
                continue
            head = line[0]
            if head.isdigit() or head in "+-*":
                fields = line.split()
                cost = int(fields[npos]) if len(fields) > npos else 0
                if current is not None:
                    entry = funcs.setdefault(current, [0, 0])
                    entry[1] += cost
                    if not after_calls:
                        entry[0] += cost
                after_calls = False
                continue
            key, _, value = line.partition("=")
            if key == "fn":
                current = _function_name(names, value)
            elif key == "calls":
                after_calls = True
    return funcs


REVERB_FUNCTION = "underfoot::engine::Convolver::process("


def function_per_part(path, prefix, names=None):
    """Inclusive instructions of the functions whose name starts with `prefix`, per part of a
    combined callgrind file, in one pass over it: {byte offset of the part: inclusive}. When
    several functions match (GCC's `[clone .part.0]` of a function is called by the function
    itself), a part's figure is the largest of their inclusive costs, i.e. the outer one's.
    Parts where none runs are absent."""
    if names is None:
        names = read_names(path)
    targets = {k for k, v in names["fn"].items() if v.startswith(prefix)}
    result = {}
    if not targets:
        return result
    npos = 1
    part_offset = 0
    per_fn = {}
    current_is_target = False
    current = None

    def close_part():
        if per_fn:
            result[part_offset] = max(per_fn.values())

    offset = 0
    with open(path, "rb") as f:
        for raw in f:
            line_offset = offset
            offset += len(raw)
            if raw.startswith(b"part:"):
                close_part()
                per_fn = {}
                part_offset = line_offset
                current_is_target = False
                continue
            if raw.startswith(b"positions:"):
                npos = len(raw.split(b":", 1)[1].split())
                continue
            if raw.startswith(b"fn="):
                value = raw[3:].decode("utf-8", "replace").strip()
                key = value[1:value.find(")")] if value.startswith("(") else None
                if key is not None and key not in names["fn"]:
                    key = None
                current = key
                current_is_target = key in targets
                continue
            if current_is_target and raw[:1] and (raw[:1].isdigit() or raw[:1] in b"+-*"):
                fields = raw.split()
                cost = int(fields[npos]) if len(fields) > npos else 0
                per_fn[current] = per_fn.get(current, 0) + cost
    close_part()
    return result


# --- figures ---------------------------------------------------------------------------------


def block_stats(counts):
    """median, p99 and worst of per-block counts, as engine/render/SceneBench computes them for
    times (sorted[n / 2], sorted[min(n - 1, n * 99 / 100)], the largest), and the worst block's
    index (the first one if several are equal)."""
    if not counts:
        raise ValueError("no blocks")
    s = sorted(counts)
    n = len(s)
    median = s[n // 2]
    p99 = s[min(n - 1, n * 99 // 100)]
    worst = s[-1]
    return {
        "blocks": n,
        "median": median,
        "p99": p99,
        "worst": worst,
        "worst_block": counts.index(worst),
        "median_block": counts.index(median),
        "worst_over_median": worst / median if median else float("inf"),
        "p99_over_median": p99 / median if median else float("inf"),
    }


def scene_counts(parts, scene):
    """The per-block totals of one scene, in block order, from read_parts' list. Raises if a
    block is missing or repeated (the dumps must cover the scene's blocks 0 .. n-1)."""
    by_block = {}
    for label, total, offset in parts:
        if label is None:
            continue
        name, _, block = label.rpartition(" ")
        if name != scene:
            continue
        b = int(block)
        if b in by_block:
            raise ValueError(f"{scene}: block {b} dumped twice")
        by_block[b] = (total, offset)
    n = len(by_block)
    if n == 0 or sorted(by_block) != list(range(n)):
        raise ValueError(f"{scene}: the dumps do not cover blocks 0..{n - 1}")
    return [by_block[b][0] for b in range(n)], [by_block[b][1] for b in range(n)]


def short_name(fn, width=70):
    """A C++ function name without its argument list and namespaces, cut to `width`."""
    fn = fn.replace("(anonymous namespace)::", "")
    depth = 0
    cut = len(fn)
    for i, ch in enumerate(fn):
        if ch == "(" and depth == 0 and i > 0:
            cut = i
            break
        if ch == "<":
            depth += 1
        elif ch == ">":
            depth -= 1
    name = fn[:cut].replace("underfoot::engine::", "").replace("underfoot::", "")
    return name if len(name) <= width else name[: width - 3] + "..."


# --- running ---------------------------------------------------------------------------------


def valgrind_command(underfoot, out_file, seconds, scene):
    return (["valgrind", *VALGRIND_OPTIONS, f"--callgrind-out-file={out_file}", underfoot,
             "bench", "--only", "scene-instructions", "--seconds", f"{seconds:g}", "--scene",
             scene])


def program_copy(underfoot, work):
    """A copy of the program without its debug sections (objcopy --strip-debug: the code and the
    symbol table stay, byte for byte). callgrind writes a cost line per source line when it
    has line tables (--dump-line=no does not stop it: with no other position it falls back to
    lines), so with them a block's dump is about 2.3x larger and the run about 2-3x slower.
    Returns the copy's path, or `underfoot` itself when objcopy is missing."""
    if shutil.which("objcopy") is None:
        print("scene_block_instructions: no objcopy (binutils): running the program with its "
              "debug sections (larger dumps, slower)", file=sys.stderr)
        return underfoot
    # Beside the program, so that the copy still runs from its build tree and reads the source
    # tree's data (base/DataDir.h: a program elsewhere reads only an installed share/underfoot).
    copy = os.path.join(os.path.dirname(os.path.abspath(underfoot)),
                        f"underfoot-nodebug-{os.getpid()}")
    subprocess.run(["objcopy", "--strip-debug", underfoot, copy], check=True)
    return copy


def run_scene(underfoot, work, seconds, scene, keep):
    """Runs one scene under callgrind and reads its dumps; removes the file unless `keep`.
    Returns (scene info, figures, per-block counts, seconds of valgrind)."""
    out_file = os.path.join(work, scene.replace("+", "_") + ".callgrind")
    cmd = valgrind_command(underfoot, out_file, seconds, scene)
    print("$ " + " ".join(cmd), file=sys.stderr, flush=True)
    t0 = time.monotonic()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    elapsed = time.monotonic() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{scene}: valgrind exited with {proc.returncode}:\n"
                           f"{proc.stderr[-3000:]}\n{proc.stdout[-1000:]}")
    info = None
    for line in proc.stdout.splitlines():
        if line.startswith("scene " + scene + " "):
            info = parse_scene_line(line)
    if info is None:
        raise RuntimeError(f"{scene}: no 'scene' line in the output:\n{proc.stdout[-2000:]}")
    try:
        st, counts = report_scene(out_file, info, TOP)
    finally:
        if not keep:
            os.remove(out_file)
    return info, st, counts, elapsed


def parse_scene_line(line):
    """`scene ID blocks N block_frames 64 rate 48000 reverb_taps T checksum C name NAME`."""
    head, _, name = line.partition(" name ")
    fields = head.split()
    info = {fields[i]: fields[i + 1] for i in range(0, len(fields) - 1, 2)}
    return {
        "id": info["scene"],
        "blocks": int(info["blocks"]),
        "block_frames": int(info["block_frames"]),
        "rate": int(info["rate"]),
        "reverb_taps": int(info["reverb_taps"]),
        "checksum": float(info["checksum"]),
        "name": name.strip(),
    }


TOP = 8  # functions listed per worst block (--top)


def report_scene(out_file, info, top):
    parts = read_parts(out_file)
    counts, offsets = scene_counts(parts, info["id"])
    if len(counts) != info["blocks"]:
        raise RuntimeError(f"{info['id']}: {len(counts)} dumps for {info['blocks']} blocks")
    st = block_stats(counts)
    st["seconds_per_block"] = info["block_frames"] / info["rate"]
    st["bytes"] = os.path.getsize(out_file)
    names = read_names(out_file)
    worst = read_functions(out_file, offsets[st["worst_block"]], names)
    median = read_functions(out_file, offsets[st["median_block"]], names)
    rows = sorted(worst.items(), key=lambda kv: -kv[1][1])
    st["functions"] = [(fn, c[0], c[1], median.get(fn, [0, 0])[1]) for fn, c in rows[:top]]
    # What the worst block has that the median block has not: self instructions, largest excess.
    excess = []
    for fn in set(worst) | set(median):
        d = worst.get(fn, [0, 0])[0] - median.get(fn, [0, 0])[0]
        excess.append((d, fn))
    excess.sort(reverse=True)
    st["excess"] = [(fn, d) for d, fn in excess[:top] if d > 0]
    # The reverb's own instructions per block (the convolver called by the scene, inclusive).
    if info["reverb_taps"]:
        reverb = function_per_part(out_file, REVERB_FUNCTION, names)
        per_block = [reverb.get(o, 0) for o in offsets]
        if all(per_block):
            st["reverb"] = block_stats(per_block)
            st["reverb_at_scene_worst"] = per_block[st["worst_block"]]
    return st, counts


def main(argv=None):
    global TOP
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--underfoot", default=os.path.join(REPO, "build", "app", "cli", "underfoot"),
                    help="the underfoot program (default: build/app/cli/underfoot)")
    ap.add_argument("--seconds", type=float, default=5.0,
                    help="as `underfoot bench --seconds`: a walk of twice that (default 5)")
    ap.add_argument("--scene", action="append", default=[],
                    help="this scene only (repeatable; default: every shipped scene, as "
                         "`underfoot bench --only scene-instructions --list-scenes` lists them)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                    help="valgrind processes at a time (default: the CPUs)")
    ap.add_argument("--top", type=int, default=TOP, help="functions listed per worst block")
    ap.add_argument("--csv", metavar="FILE", help="also write every block: scene,block,time_s,"
                                                   "instructions")
    ap.add_argument("--with-debug", action="store_true",
                    help="run the program itself, not a copy without debug sections (dumps per "
                         "source line, for callgrind_annotate with --keep)")
    ap.add_argument("--keep", metavar="DIR",
                    help="write the callgrind files into DIR and keep them (default: a "
                         "temporary folder; each file is removed once read)")
    args = ap.parse_args(argv)
    TOP = args.top

    if shutil.which("valgrind") is None:
        print("scene_block_instructions: valgrind is not installed (apt-get install valgrind)",
              file=sys.stderr)
        return 2
    underfoot = os.path.abspath(args.underfoot)
    if not os.access(underfoot, os.X_OK):
        print(f"scene_block_instructions: no program {underfoot} (build it, or --underfoot)",
              file=sys.stderr)
        return 2
    scenes = args.scene
    if not scenes:
        listed = subprocess.run([underfoot, "bench", "--only", "scene-instructions",
                                 "--list-scenes"], capture_output=True, text=True, check=True)
        scenes = listed.stdout.split()
    copies = []
    work = args.keep or tempfile.mkdtemp(prefix="scene_blocks_")
    os.makedirs(work, exist_ok=True)
    t0 = time.monotonic()
    try:
        program = underfoot if args.with_debug else program_copy(underfoot, work)
        if program != underfoot:
            copies.append(program)
        with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            results = list(pool.map(
                lambda s: run_scene(program, work, args.seconds, s, bool(args.keep)), scenes))
    except (RuntimeError, ValueError) as e:
        print(f"scene_block_instructions: {e}", file=sys.stderr)
        return 1
    finally:
        for c in copies:
            os.remove(c)
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    wall = time.monotonic() - t0

    if args.csv:
        with open(args.csv, "w", encoding="utf-8") as f:
            f.write("scene,block,time_s,instructions\n")
            for info, st, counts, _ in results:
                for b, c in enumerate(counts):
                    f.write(f"{info['id']},{b},{b * st['seconds_per_block']:.6f},{c}\n")

    print(f"### Instructions per 64-frame block (callgrind), walks of {2 * args.seconds:g} s\n")
    scene_args = "".join(f" --scene {s}" for s in args.scene)
    print(f"`python3 tools/perf/scene_block_instructions.py --seconds {args.seconds:g}{scene_args}`"
          f" ({os.path.relpath(underfoot, REPO)}): {wall:.0f} s wall clock, "
          f"{min(max(1, args.jobs), len(scenes))} valgrind process(es) at a time.\n")
    print("| scene | reverb taps | blocks | median | p99 | worst | p99 / median | worst / median "
          "| worst block (start) | worst <= 2x median |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for info, st, _, _ in results:
        t = st["worst_block"] * st["seconds_per_block"]
        print(f"| {info['name']} | {info['reverb_taps'] or '-'} | {st['blocks']} | "
              f"{st['median']:,} | {st['p99']:,} | {st['worst']:,} | "
              f"{st['p99_over_median']:.2f} | {st['worst_over_median']:.2f} | "
              f"{st['worst_block']} ({t:.3f} s) | "
              f"{'yes' if st['worst'] <= 2 * st['median'] else 'no'} |")
    print()
    with_reverb = [(info, st) for info, st, _, _ in results if "reverb" in st]
    if with_reverb:
        print("The reverb's own instructions per block (`Convolver::process`, inclusive), in the "
              "same runs:\n")
        print("| scene | reverb taps | median | p99 | worst | worst / median | worst block (start) "
              "| the scene's worst block: reverb / the reverb's median |")
        print("|---|---:|---:|---:|---:|---:|---|---:|")
        for info, st in with_reverb:
            r = st["reverb"]
            t = r["worst_block"] * st["seconds_per_block"]
            at_scene_worst = st["reverb_at_scene_worst"] / r["median"]
            print(f"| {info['name']} | {info['reverb_taps']} | {r['median']:,} | {r['p99']:,} | "
                  f"{r['worst']:,} | {r['worst_over_median']:.2f} | {r['worst_block']} "
                  f"({t:.3f} s) | {at_scene_worst:.2f} |")
        print()
    for info, st, _, elapsed in results:
        t = st["worst_block"] * st["seconds_per_block"]
        mt = st["median_block"] * st["seconds_per_block"]
        print(f"#### {info['name']}: worst block {st['worst_block']} ({t:.3f} s, "
              f"{st['worst']:,} instructions) against a median block, {st['median_block']} "
              f"({mt:.3f} s, {st['median']:,})\n")
        print(f"valgrind {elapsed:.0f} s, callgrind file {st['bytes'] / 1e6:.0f} MB, "
              f"checksum {info['checksum']:.9g}.\n")
        print("| function | inclusive, worst block | self, worst block | inclusive, median "
              "block |\n|---|---:|---:|---:|")
        for fn, self_cost, incl, med in st["functions"]:
            print(f"| `{short_name(fn)}` | {incl:,} | {self_cost:,} | {med:,} |")
        print("\nLargest excess of self instructions, worst block - median block: " +
              "; ".join(f"`{short_name(fn, 50)}` +{d:,}" for fn, d in st["excess"]) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
