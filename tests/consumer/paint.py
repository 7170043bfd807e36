"""The installed Python module: imported from the install prefix, it paints a short stroke."""
import sys

import numpy as np
import wetbrush

prefix = sys.argv[1]
assert wetbrush.__file__.startswith(prefix), f"imported {wetbrush.__file__}, not from {prefix}"
brush = {"shape": "round", "bristles": 40, "length": 24.0, "width": 8.0, "thickness": 8.0, "samples_per_bristle": 32}
s = wetbrush.Session(canvas=(64, 64, 16), device="cpu", window=(48, 48, 16), brush=brush)
s.paint(np.linspace(20.0, 40.0, 8), np.full(8, 32.0), np.array([0.6] * 7 + [0.0]))
h = s.height()
assert h.max() > 0.0, "no paint"
print(f"installed module {wetbrush.__file__}: paint {h.max():.2f} cells high")
