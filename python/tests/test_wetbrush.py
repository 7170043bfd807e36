"""The Python module: a stroke becomes maps, parameters by id, bad input raises wetbrush.Error
with the core's message, and a batch of stroke files replays on one device.

Small canvases and short strokes on the CPU backend (the scenes of the core's tests)."""
import math
import os
import pathlib

import numpy as np
import pytest

import wetbrush

SOURCE = pathlib.Path(os.environ.get("WB_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
CANVAS = (128, 96, 16)
WINDOW = (64, 64, 16)
SMALL = {"particles.D0": 8.0, "particles.D1": 4.0}
# A small round brush (the core's whole-step tests' brush): 40 bristles 8 mm long.
BRUSH = {"shape": "round", "bristles": 40, "length": 40.0, "width": 12.0, "thickness": 12.0, "samples_per_bristle": 64}


def small_session(**kw):
    return wetbrush.Session(canvas=CANVAS, device="cpu", brush=BRUSH, window=WINDOW, params=SMALL, **kw)


def drag(n=24):
    """A pressed drag of 40 cells across the canvas's middle, 200 samples a second."""
    x = np.linspace(40.0, 80.0, n)
    y = np.full(n, 48.0)
    p = np.full(n, 0.6)
    p[-1] = 0.0  # the lift
    return x, y, p


@pytest.fixture(scope="module")
def painted():
    s = small_session(undo=2)
    x, y, p = drag()
    report = s.paint(x, y, p, color=(0.05, 0.1, 0.9), oil=0.3)
    return s, report


def test_a_stroke_becomes_maps(painted):
    s, report = painted
    assert report["steps"] > 0 and report["nonfinite_events"] == 0
    assert abs(report["drift"]) < 1e-4
    h = s.height()
    assert h.dtype == np.float32 and h.shape == (CANVAS[1], CANVAS[0])
    assert np.isfinite(h).all() and h.min() >= 0.0 and h.max() <= CANVAS[2]
    # Paint along the drag, none far from it.
    assert h[44:53, 45:75].max() > 0.2
    assert h[:, 110:].max() == 0.0 and h[85:, :].max() == 0.0
    n = s.normal()
    assert n.shape == (CANVAS[1], CANVAS[0], 3)
    assert np.allclose(np.linalg.norm(n, axis=2), 1.0, atol=1e-3)
    a = s.albedo()
    assert a.shape == (CANVAS[1], CANVAS[0], 3)
    # The blue paint is blue where it lies thickest.
    yy, xx = np.unravel_index(np.argmax(h), h.shape)
    assert a[yy, xx, 2] > a[yy, xx, 0]
    ryb = s.pick(int(xx), int(yy))
    assert ryb is not None and ryb[2] > ryb[0]
    assert s.pick(120, 90) is None
    img = s.render()
    assert img.shape == (CANVAS[1], CANVAS[0], 4) and img.dtype == np.uint8
    # No copy: the array owns the core's image.
    assert h.flags["OWNDATA"] is False and h.base is not None


def test_undo_and_files(painted, tmp_path):
    s, _ = painted
    before = s.height()
    path = str(tmp_path / "p.ora")
    s.save(path)
    o = wetbrush.Session.open(path, device="cpu")
    assert o.canvas == CANVAS
    assert np.abs(o.height() - before).max() < 1e-3
    scale = o.export_maps(height=str(tmp_path / "h.png"), albedo=str(tmp_path / "a.png"))
    assert scale > 0 and (tmp_path / "h.png").stat().st_size > 0
    assert s.undo() is True
    assert s.height().max() < 1e-3
    assert s.redo() is True
    assert np.abs(s.height() - before).max() < 1e-3


def test_palette_verbs_ground_and_regions():
    s = small_session(undo=4)
    s.lay_ground({"weave": "linen"})
    primed = s.height()
    assert primed.min() > 0.0, "the primer lies under the weave's hollows"
    assert primed.max() - primed.min() > 0.5, "the weave's relief"
    s.dip((0.05, 0.1, 0.9), oil=0.4, load=1.0)
    s.wipe(0.2)
    x, y, p = drag(12)
    s.paint(x, y, p, color=(0.05, 0.1, 0.9))
    assert s.albedo()[48, 60, 2] > s.albedo()[48, 60, 0]
    s.paint(x, y + 20.0, p, color=(0.9, 0.1, 0.05))
    assert s.undo() is True, "the second stroke goes"
    s.clean()
    before = s.census()["total"]
    s.dry()
    assert s.undo() is False, "drying starts a new history"
    assert s.census()["total"] == pytest.approx(before, rel=1e-6), "the first stroke stays"
    img = s.render(region=(40, 40, 32, 16), zoom=2)
    assert img.shape == (32, 64, 4)
    with pytest.raises(wetbrush.Error, match="in \\[0, 1\\]"):
        s.dip((2.0, 0.0, 0.0))
    with pytest.raises(wetbrush.Error):
        s.wipe(math.nan)
    with pytest.raises(wetbrush.Error, match="weave"):
        s.lay_ground({"weave": "silk"})


def test_parameters_by_id():
    table = {p["id"]: p for p in wetbrush.params()}
    assert "grid.tilt" in table and table["grid.tilt"]["unit"]
    s = small_session()
    assert s.param("particles.D0") == pytest.approx(8.0)
    assert s.param("grid.tilt") == pytest.approx(table["grid.tilt"]["default"])
    s.set_params({"grid.tilt": 30.0})
    assert s.param("grid.tilt") == pytest.approx(30.0)
    with pytest.raises(wetbrush.Error, match="grid.tilt"):
        s.set_params({"grid.tilt": 1000.0})
    with pytest.raises(wetbrush.Error, match="unknown parameter"):
        s.param("no.such")


def test_bad_input_raises_the_cores_message(tmp_path):
    s = small_session()
    x, y, p = drag(4)
    with pytest.raises(wetbrush.Error, match="y has 3 values"):
        s.paint(x, y[:3], p)
    with pytest.raises(wetbrush.Error):
        s.paint(x, y, np.array([0.5, math.nan, 0.5, 0.0]))
    with pytest.raises(wetbrush.Error, match="canvas"):
        s.paint(x + 500.0, y, p)  # off the canvas
    bad = tmp_path / "bad.json"
    bad.write_text('{"canvas": {"width": 64, "height": 64, "depth": 16}, "samples": [[0, 1]]}')
    with pytest.raises(wetbrush.Error, match="bad.json"):
        s.replay(str(bad))
    with pytest.raises(wetbrush.Error):
        wetbrush.Session.open(str(tmp_path / "missing.ora"), device="cpu")
    with pytest.raises(wetbrush.Error):
        wetbrush.Session(canvas=CANVAS, device="nonsense")


def test_a_batch_of_stroke_files_on_one_device(tmp_path):
    # Three strokes written as files, then replayed each on its own session on one device, as
    # `wetbrush replay` would: their maps differ where their strokes do.
    for i, color in enumerate([(0.9, 0.1, 0.05), (0.1, 0.8, 0.1), (0.05, 0.1, 0.9)]):
        x, y, p = drag(12)
        st = wetbrush.Stroke.from_arrays(CANVAS, x, y + 15.0 * (i - 1), p, brush=BRUSH, color=color)
        st.save(str(tmp_path / f"stroke{i}.json"))
    heights = []
    for f in sorted(tmp_path.glob("stroke*.json")):
        st = wetbrush.Stroke.load(str(f))
        assert st.canvas == CANVAS and st.samples.shape == (12, 8)
        s = wetbrush.Session.for_stroke(st, device="cpu", params=SMALL, window=WINDOW)
        report = s.replay(st)
        assert report["steps"] > 0 and abs(report["drift"]) < 1e-4
        heights.append(s.height())
    rows = [int(np.argmax(h.sum(axis=1))) for h in heights]
    assert rows[0] < rows[1] < rows[2], rows  # each stroke where its file put it
    # A replay can be cancelled from its progress callback.
    s = wetbrush.Session.for_stroke(st, device="cpu", params=SMALL, window=WINDOW)
    with pytest.raises(wetbrush.Error, match="cancelled"):
        s.replay(st, progress=lambda done, total: done < 3)
