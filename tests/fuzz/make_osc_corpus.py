#!/usr/bin/env python3
# Writes the seed corpus of fuzz_osc_packet (tests/fuzz/corpus/osc_packet/): the datagrams that
# tests/live/sensors/test_osc_gyro.cpp sends with liblo's lo_send (OSC 1.0 encoding: padded
# address, padded ",tags", big-endian arguments), plus doubles and a bundle of the four limbs.
import math, os, struct

d = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "osc_packet")
os.makedirs(d, exist_ok=True)
for f in os.listdir(d):
    os.remove(os.path.join(d, f))

def pad(b):
    b += b"\0"
    return b + b"\0" * (-len(b) % 4)

def msg(path, tags, *args):
    out = pad(path.encode()) + pad(("," + tags).encode())
    for t, a in zip(tags, args):
        out += {"f": lambda v: struct.pack(">f", v), "i": lambda v: struct.pack(">i", v),
                "d": lambda v: struct.pack(">d", v), "s": lambda v: pad(v.encode())}[t](a)
    return out

def bundle(*elements):
    out = b"#bundle\0" + struct.pack(">Q", 1)
    for e in elements:
        out += struct.pack(">i", len(e)) + e
    return out

limbs = ["left_thigh", "right_thigh", "left_shank", "right_shank"]
g = "/underfoot/gyro/"
seeds = {
    "fi_left_thigh": msg(g + "left_thigh", "fi", 80 * math.sin(0.05 * 3), 3),
    "f_right_thigh": msg(g + "right_thigh", "f", -41.5),
    "fi_left_shank": msg(g + "left_shank", "fi", 10.0, 104),
    "d_right_shank": msg(g + "right_shank", "d", 123.25),
    "di_left_thigh": msg(g + "left_thigh", "di", -7.5, 2**31 - 1),
    "unknown_limb": msg(g + "left_knee", "f", 1.0),
    "string_arg": msg(g + "left_thigh", "s", "fast"),
    "nan": msg(g + "left_thigh", "fi", float("nan"), 3),
    "inf": msg(g + "right_shank", "f", float("inf")),
    "garbage": b"garbage, not OSC",
    "bundle_four_limbs": bundle(*[msg(g + l, "fi", 5.0 * i, 42) for i, l in enumerate(limbs)]),
    "bundle_nested": bundle(msg(g + "left_thigh", "f", 1.0),
                            bundle(msg(g + "right_shank", "fi", 2.0, 9))),
}
for name, data in seeds.items():
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)
print(f"{len(seeds)} seeds in {d}")
