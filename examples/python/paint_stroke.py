#!/usr/bin/env python3
"""Paints one S-shaped stroke with a pressure swell and saves its maps.

    PYTHONPATH=build/bin python3 examples/python/paint_stroke.py OUT_DIR [--device cpu|cuda|auto]

Writes OUT_DIR/stroke.ora (the painting, which the studio opens), height.png, normal.png and
albedo.png (as `wetbrush export`), and height.npy (float32 cells, 0.2 mm each)."""
import argparse
import pathlib

import numpy as np

import wetbrush


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=pathlib.Path)
    ap.add_argument("--device", default="auto")
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)

    # A 64 x 48 mm canvas 3.2 mm deep; the default round brush (200 bristles, 20 mm long).
    s = wetbrush.Session(canvas=(320, 240, 16), device=a.device, brush="round")
    # 1.2 s of pen at 200 samples a second: an S across the canvas, pressure rising then easing.
    u = np.linspace(0.0, 1.0, 240)
    x = 60.0 + 200.0 * u
    y = 120.0 + 50.0 * np.sin(2.0 * np.pi * u)
    pressure = 0.25 + 0.45 * np.sin(np.pi * u)
    pressure[-1] = 0.0  # the lift
    report = s.paint(x, y, pressure, rate=200.0, color=(0.1, 0.2, 0.85), oil=0.3)
    print(f"painted {report['steps']} steps on {s.device}; paint drift {report['drift']:.2e}")

    height = s.height()
    np.save(a.out / "height.npy", height)
    s.export_maps(height=str(a.out / "height.png"), normal=str(a.out / "normal.png"), albedo=str(a.out / "albedo.png"))
    s.save(str(a.out / "stroke.ora"))
    print(f"highest paint {height.max() * 0.2:.2f} mm; wrote {a.out}/stroke.ora and its maps")


if __name__ == "__main__":
    main()
