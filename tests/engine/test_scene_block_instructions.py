#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""tools/perf/scene_block_instructions.py: reading callgrind's per-block dumps, the
block figures, and (when valgrind is installed and the build is not sanitized) one short scene
through `underfoot bench --only scene-instructions` under callgrind.

    UNDERFOOT_CLI=build/app/cli/underfoot python3 tests/engine/test_scene_block_instructions.py
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT_DIR = os.path.join(HERE, "..", "..", "tools", "perf")
sys.path.insert(0, SCRIPT_DIR)
import scene_block_instructions as sbi  # noqa: E402

# A combined callgrind file as callgrind 3.19 writes it with --combine-dumps=yes: three block
# dumps of scene "s+x", then the dump at program termination (no label; its summary is garbage,
# as callgrind writes it after CALLGRIND_STOP_INSTRUMENTATION). Names are compressed: defined
# once ("fn=(11) child(int)"), then referred to by number, across parts.
CALLGRIND = """# callgrind format
version: 1
creator: callgrind-3.19.0
pid: 1
cmd:  underfoot bench --only scene-instructions --scene s+x
part: 1


desc: I1 cache: 
desc: Timerange: Basic block 0 - 10
desc: Trigger: Client Request: s+x 0

positions: line
events: Ir
summary: 100


ob=(1) /tmp/underfoot
fl=(1) ???
fn=(10) top(underfoot::engine::(anonymous namespace)::Args const&)
0 10
cfn=(11) underfoot::engine::child(int)
calls=1 0 
0 90

fn=(11)
0 90

totals: 100

part: 2

desc: Timerange: Basic block 10 - 30
desc: Trigger: Client Request: s+x 1

positions: line
events: Ir
summary: 300


ob=(1)
fl=(1)
fn=(10)
0 5
cfn=(11)
calls=2 0 
0 295

fn=(11)
0 200
+1 50
cob=(2) /usr/lib/x86_64-linux-gnu/libc.so.6
cfi=(2) ./string/memset.S
cfn=(12) __memset_avx2_unaligned_erms
calls=1 167 
0 45

ob=(2)
fl=(2)
fn=(12)
167 45

totals: 300

part: 3

desc: Timerange: Basic block 30 - 40
desc: Trigger: Client Request: s+x 2

positions: line
events: Ir
summary: 200


ob=(1)
fl=(1)
fn=(10)
0 200

totals: 200

part: 4

desc: Timerange: Basic block 40 - 41
desc: Trigger: Program termination

positions: line
events: Ir
summary: 18446744073635007179


ob=(1)
fl=(1)
fn=(10)
0 21

totals: 21
"""


class ReadingDumps(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.path = os.path.join(self.dir, "s.callgrind")
        with open(self.path, "w", encoding="utf-8") as f:
            f.write(CALLGRIND)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def test_every_part_with_its_label_and_total(self):
        parts = sbi.read_parts(self.path)
        self.assertEqual([(p[0], p[1]) for p in parts],
                         [("s+x 0", 100), ("s+x 1", 300), ("s+x 2", 200), (None, 21)])
        with open(self.path, "rb") as f:
            data = f.read()
        for _, _, offset in parts:
            self.assertTrue(data[offset:].startswith(b"part: "))

    def test_scene_counts_in_block_order_and_refuses_gaps(self):
        parts = sbi.read_parts(self.path)
        counts, offsets = sbi.scene_counts(parts, "s+x")
        self.assertEqual(counts, [100, 300, 200])
        self.assertEqual(len(offsets), 3)
        with self.assertRaises(ValueError):
            sbi.scene_counts([p for p in parts if p[0] != "s+x 1"], "s+x")
        with self.assertRaises(ValueError):
            sbi.scene_counts(parts + [parts[0]], "s+x")
        with self.assertRaises(ValueError):
            sbi.scene_counts(parts, "other")

    def test_self_and_inclusive_per_function_of_one_part(self):
        parts = sbi.read_parts(self.path)
        names = sbi.read_names(self.path)
        # Part 2 uses the names part 1 defined.
        fns = sbi.read_functions(self.path, parts[1][2], names)
        top = "top(underfoot::engine::(anonymous namespace)::Args const&)"
        self.assertEqual(fns[top], [5, 300])
        self.assertEqual(fns["underfoot::engine::child(int)"], [250, 295])
        self.assertEqual(fns["__memset_avx2_unaligned_erms"], [45, 45])
        self.assertEqual(sum(v[0] for v in fns.values()), 300)  # self costs add up to totals
        self.assertEqual(sbi.read_functions(self.path, parts[2][2]), {top: [200, 200]})

    def test_one_function_inclusive_per_part_in_one_pass(self):
        parts = sbi.read_parts(self.path)
        offsets = [p[2] for p in parts]
        # child(int) runs in parts 1 and 2 only: inclusive 90, then 250 + 45 (its memset call).
        got = sbi.function_per_part(self.path, "underfoot::engine::child(")
        self.assertEqual(got, {offsets[0]: 90, offsets[1]: 295})
        # Two matching functions (an outer one and what it calls): the outer one's figure.
        got = sbi.function_per_part(self.path, "")
        self.assertEqual(got, {offsets[0]: 100, offsets[1]: 300, offsets[2]: 200,
                               offsets[3]: 21})
        self.assertEqual(sbi.function_per_part(self.path, "nothing("), {})

    def test_figures_as_scene_bench_computes_them(self):
        counts = list(range(1, 201))  # 200 blocks: median s[100], p99 s[198]
        st = sbi.block_stats(counts)
        self.assertEqual((st["median"], st["p99"], st["worst"]), (101, 199, 200))
        self.assertEqual(st["worst_block"], 199)
        self.assertEqual(st["median_block"], 100)
        self.assertAlmostEqual(st["worst_over_median"], 200 / 101)
        st = sbi.block_stats([5, 9, 5, 9, 1])
        self.assertEqual((st["median"], st["worst"], st["worst_block"]), (5, 9, 1))
        with self.assertRaises(ValueError):
            sbi.block_stats([])

    def test_short_names_and_the_scene_line(self):
        self.assertEqual(
            sbi.short_name("underfoot::engine::(anonymous namespace)::ImpactLayer::process("
                           "float const*, float*, int)"), "ImpactLayer::process")
        self.assertEqual(sbi.short_name("void underfoot::engine::(anonymous namespace)::macAvx<2,"
                                        " true>(Mac const&, int)"), "void macAvx<2, true>")
        info = sbi.parse_scene_line("scene a+b+c blocks 7671 block_frames 64 rate 48000 "
                                    "reverb_taps 105600 checksum 312.688422 name a + b + c")
        self.assertEqual(info["id"], "a+b+c")
        self.assertEqual(info["name"], "a + b + c")
        self.assertEqual((info["blocks"], info["reverb_taps"]), (7671, 105600))


CLI = os.environ.get("UNDERFOOT_CLI", "")


@unittest.skipUnless(CLI and os.access(CLI, os.X_OK), "UNDERFOOT_CLI is not set")
class TheModeOutsideValgrind(unittest.TestCase):
    def test_refuses_with_a_message_naming_valgrind_and_the_script(self):
        r = subprocess.run([CLI, "bench", "--only", "scene-instructions", "--seconds", "0.5"],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertIn("valgrind", r.stderr)
        self.assertIn("tools/perf/scene_block_instructions.py", r.stderr)
        self.assertEqual(r.stdout, "")

    def test_lists_the_shipped_scenes_and_refuses_an_unknown_one(self):
        r = subprocess.run([CLI, "bench", "--only", "scene-instructions", "--list-scenes"],
                           capture_output=True, text=True, check=True)
        scenes = r.stdout.split()
        for s in ("wood_reverb", "metal_reverb", "creaking_wood_reverb",
                  "creaking_wood+hall+forest", "gravel+farm_courtyard"):
            self.assertIn(s, scenes)
        r = subprocess.run([CLI, "bench", "--only", "scene-instructions", "--scene", "nope"],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 2)
        self.assertIn("no shipped scene 'nope'", r.stderr)
        self.assertIn("wood_reverb", r.stderr)


@unittest.skipUnless(CLI and os.access(CLI, os.X_OK), "UNDERFOOT_CLI is not set")
@unittest.skipIf(shutil.which("valgrind") is None, "valgrind is not installed")
@unittest.skipIf(os.environ.get("UNDERFOOT_SANITIZED") == "1",
                 "a sanitized build does not run under valgrind")
class OneSceneUnderCallgrind(unittest.TestCase):
    def test_every_block_counted_and_the_worst_block_explained(self):
        out = tempfile.mkdtemp()
        try:
            csv = os.path.join(out, "blocks.csv")
            r = subprocess.run([sys.executable, os.path.join(SCRIPT_DIR,
                                                             "scene_block_instructions.py"),
                                "--underfoot", CLI, "--seconds", "0.5", "--scene", "wood_reverb",
                                "--csv", csv, "--top", "8"],
                               capture_output=True, text=True, timeout=120)
            self.assertEqual(r.returncode, 0, r.stderr[-3000:])
            self.assertIn("--tool=callgrind", r.stderr)  # the command is named
            # Two rows: the scene's blocks, then the reverb's own instructions per block.
            row = [ln for ln in r.stdout.splitlines() if ln.startswith("| wood_reverb |")]
            self.assertEqual(len(row), 2, r.stdout)
            cells = [c.strip() for c in row[0].strip("|").split("|")]
            reverb = [c.strip() for c in row[1].strip("|").split("|")]
            self.assertEqual(reverb[1], "42240")
            reverb_median, reverb_worst = (int(reverb[i].replace(",", "")) for i in (2, 4))
            self.assertGreater(reverb_median, 1000)  # the convolver ran in every block
            self.assertGreaterEqual(reverb_worst, reverb_median)
            self.assertEqual(cells[1], "42240")
            blocks = int(cells[2])
            median, worst = (int(cells[i].replace(",", "")) for i in (3, 5))
            self.assertGreater(median, 10000)  # a block of scene and reverb, not an empty dump
            self.assertGreaterEqual(worst, median)
            self.assertLess(reverb_median, median)  # a part of the scene's block
            with open(csv, encoding="utf-8") as f:
                lines = f.read().split()
            self.assertEqual(len(lines), blocks + 1)
            self.assertIn("`FootstepScene::process`", r.stdout)  # the worst block's functions
            self.assertIn("`Surface::process`", r.stdout)  # (which of the surface and the
            # reverb leads the worst block depends on the presets: not asserted)
        finally:
            shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    unittest.main()
