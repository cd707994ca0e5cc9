# SPDX-License-Identifier: GPL-3.0-or-later
"""What the listener scripts under realism/ share: the 14 scalar descriptors of
realism/Descriptors.h (in `underfoot compare --features` order), their spread floors, the
category of each recorded material (realism/Listener.cpp, categoryOfMaterial) and a linear
quantile. Imported by listener_grid.py, listener_lda.py, category_why.py and material_spread.py
(run from any folder: Python puts the script's own folder first on its path)."""
import math

NS = 14  # scalar descriptors (realism/Descriptors.h)
KEYS = ["centroid", "rolloff85", "flatness", "band_20_250", "band_250_1k", "band_1k_4k",
        "band_4k_16k", "peakiness", "grain_rate", "crest", "decay20", "attack", "active",
        "temporal_centroid"]
FLOORS = [0.5, 0.5, 3, 3, 3, 3, 3, 3, 0.5, 3, 0.5, 0.5, 0.5, 0.5]
CATEGORY = {"wood": "solid", "metal": "solid", "hard": "solid", "ice": "solid",
            "carpet": "solid", "gravel": "aggregate", "sand": "aggregate",
            "snow": "aggregate", "dirt": "aggregate", "grass": "aggregate", "water": "liquid"}


def quantile(v, p):
    """Linear interpolation between order statistics (R's type 7)."""
    v = sorted(v)
    h = (len(v) - 1) * p
    lo = math.floor(h)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (h - lo) * (v[hi] - v[lo])
