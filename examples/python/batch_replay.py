#!/usr/bin/env python3
"""Replays every stroke file of a folder on one device, each on its own session as `wetbrush
replay` would, and writes each painting's height map and a summary table.

    PYTHONPATH=build/bin python3 examples/python/batch_replay.py STROKES_DIR OUT_DIR [--device cuda]

For every *.json or *.txt stroke file: OUT_DIR/NAME.height.npy (float32 cells) and NAME.png (the
painting from above); OUT_DIR/summary.csv holds steps, seconds, paint drift and the paint's
highest point. A file that cannot be read is reported and skipped."""
import argparse
import csv
import pathlib
import sys
import time

import numpy as np

import wetbrush


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("strokes", type=pathlib.Path)
    ap.add_argument("out", type=pathlib.Path)
    ap.add_argument("--device", default="auto")
    ap.add_argument("--set", action="append", default=[], metavar="ID=VALUE", help="a parameter, repeatable")
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    params = {k: float(v) for k, v in (p.split("=", 1) for p in a.set)}
    files = sorted(p for p in a.strokes.iterdir() if p.suffix in (".json", ".txt"))
    if not files:
        sys.exit(f"batch_replay: no stroke files (*.json, *.txt) in {a.strokes}")
    failed = 0
    with open(a.out / "summary.csv", "w", newline="") as f:
        table = csv.writer(f)
        table.writerow(["stroke", "steps", "seconds", "drift", "highest_mm"])
        for path in files:
            try:
                stroke = wetbrush.Stroke.load(str(path))
                s = wetbrush.Session.for_stroke(stroke, device=a.device, params=params)
                t0 = time.monotonic()

                def progress(done, total):
                    print(f"\r{path.name}: step {done}/{total}", end="", flush=True)
                    return True

                report = s.replay(stroke, progress=progress)
                height = s.height()
            except wetbrush.Error as e:
                print(f"\n{path.name}: skipped: {e}")
                failed += 1
                continue
            seconds = time.monotonic() - t0
            np.save(a.out / f"{path.stem}.height.npy", height)
            wetbrush.write_png(str(a.out / f"{path.stem}.png"), s.render())
            table.writerow([path.name, report["steps"], f"{seconds:.1f}", f"{report['drift']:.2e}",
                            f"{height.max() * 0.2:.3f}"])
            print(f"\r{path.name}: {report['steps']} steps in {seconds:.1f} s on {s.device}")
    print(f"wrote {a.out}/summary.csv ({len(files) - failed} of {len(files)} strokes)")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
