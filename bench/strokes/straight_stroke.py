#!/usr/bin/env python3
"""Writes a straight stroke at a steady speed as a wetbrush stroke file (JSON, to stdout).

The brush lands at (100, 128) over 0.1 s, is drawn 200 cells (40 mm) along +x at SPEED mm/s with
pressure 0.6, the handle tilted 15 degrees, and lifts over 0.1 s; oil 0.3, a full load, on a
400 x 256 x 32 canvas. The ribs' measurement of docs/TRANSFER.md "Ribs on slow strokes":

    bench/strokes/straight_stroke.py 15 round > r15.json
    wetbrush replay r15.json --save r15.ora && wetbrush export r15.ora --height r15.png
"""
import argparse
import json

CELL_MM = 0.2
EVENT_S = 0.01


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("speed", type=float, help="drawing speed, mm/s")
    ap.add_argument("shape", nargs="?", default="round", help="brush shape (the stroke format's default brush)")
    ap.add_argument("--twist", type=float, default=0.0, help="pen twist, degrees (90 pulls a flat broadside)")
    ap.add_argument("--length", type=float, default=200.0, help="length of the drag, cells")
    a = ap.parse_args()
    if not a.speed > 0:
        ap.error("speed must be positive")
    v = a.speed / CELL_MM  # cells/s
    x0, y0 = 100.0, 128.0
    samples, t = [], 0.0

    def add(x, p):
        nonlocal t
        samples.append({"t": round(t, 4), "x": round(x, 4), "y": y0, "pressure": round(p, 4), "tilt_x": 15,
                        "tilt_y": 0, "twist": a.twist})
        t += EVENT_S

    for i in range(11):
        add(x0, 0.6 * i / 10)
    x = x0
    while x < x0 + a.length:
        x = min(x0 + a.length, x + v * EVENT_S)
        add(x, 0.6)
    for i in range(10):
        add(x, 0.6 * (1 - (i + 1) / 10))
    doc = {"format": "wetbrush-stroke", "version": 1,
           "comment": f"A straight {a.shape} stroke at {a.speed:g} mm/s (bench/strokes/straight_stroke.py).",
           "canvas": {"width": 400, "height": 256, "depth": 32},
           "brush": {"shape": a.shape},
           "paint": {"ryb": [0.9, 0.15, 0.0], "oil": 0.3, "load": 1.0, "reload_on_pen_down": False},
           "samples": samples}
    print(json.dumps(doc))


if __name__ == "__main__":
    main()
