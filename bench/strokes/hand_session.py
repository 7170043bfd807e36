#!/usr/bin/env python3
"""Writes a tablet-like painting session as a MyPaint event dump (t x y pressure xtilt ytilt).

A hand's pen path, not a plotter's: strokes of 0.3-2.5 s with minimum-jerk speed profiles
(Flash & Hogan 1985) along curved paths, peak speeds drawn from 40 to 450 mm/s (bursts above
300 mm/s in about a third of the strokes), 5 ms events with 0.4 ms clock jitter, 0.15-cell
position tremor, eased pressure with noise, slow tilt drift, hovering between strokes (pen up,
pressure 0) for 0.15-1.2 s, and a few long pauses. Positions in canvas cells (0.2 mm).

  bench/strokes/hand_session.py [--seconds 30] [--seed 7] > bench/strokes/hand-session-30s.txt
"""
import argparse
import math
import random

CELL_MM = 0.2


def min_jerk(s):  # position fraction at time fraction s
    return s * s * s * (10 - 15 * s + 6 * s * s)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--seed", type=int, default=7)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    print("# Tablet-like painting session in the MyPaint event-dump format: t x y pressure xtilt ytilt")
    print(f"# bench/strokes/hand_session.py --seconds {a.seconds:g} --seed {a.seed}: hand speeds (minimum-jerk")
    print("# strokes, peaks 40-450 mm/s), 5 ms events with jitter, tremor, pauses. Not captured from hardware.")
    t = 0.0
    x, y = 2048.0, 2048.0
    tx, ty = 0.2, -0.1
    dt_ev = 0.005

    def emit(px, py, p):
        jt = t + rng.uniform(-0.0004, 0.0004)
        print(f"{jt:.4f} {px + rng.gauss(0, 0.15):.2f} {py + rng.gauss(0, 0.15):.2f} {p:.3f} {tx:.3f} {ty:.3f}")

    while t < a.seconds:
        # Hover to the next stroke's start.
        pause = rng.uniform(0.15, 1.2) if rng.random() > 0.1 else rng.uniform(1.5, 3.0)
        sx = min(max(x + rng.uniform(-250, 250), 1500), 2600)
        sy = min(max(y + rng.uniform(-250, 250), 1500), 2600)
        n = max(2, int(pause / dt_ev))
        for i in range(n):
            s = (i + 1) / n
            emit(x + (sx - x) * min_jerk(s), y + (sy - y) * min_jerk(s), 0.0)
            t += dt_ev
        x, y = sx, sy
        # The stroke: a curved path of length L at a minimum-jerk pace.
        peak_mm_s = rng.choice([rng.uniform(40, 150), rng.uniform(150, 300), rng.uniform(300, 450)])
        length = rng.uniform(150, 900)  # cells
        dur = max(0.3, min(2.5, 1.875 * length * CELL_MM / peak_mm_s))  # minimum-jerk peak = 1.875 L / T
        heading = rng.uniform(0, 2 * math.pi)
        curve = rng.uniform(-2.0, 2.0) / length  # rad a cell
        pmax = rng.uniform(0.35, 0.95)
        n = max(4, int(dur / dt_ev))
        prev = 0.0
        for i in range(n + 1):
            s = i / n
            along = length * min_jerk(s)
            step = along - prev
            prev = along
            heading += curve * step
            x += step * math.cos(heading)
            y += step * math.sin(heading)
            ease = min(1.0, s / 0.12, (1 - s) / 0.15 + 0.05)
            p = max(0.02, min(1.0, pmax * ease + rng.gauss(0, 0.01)))
            emit(x, y, p)
            t += dt_ev
            tx = max(-1.0, min(1.0, tx + rng.gauss(0, 0.004)))
            ty = max(-1.0, min(1.0, ty + rng.gauss(0, 0.004)))
        emit(x, y, 0.0)
        t += dt_ev


if __name__ == "__main__":
    main()
