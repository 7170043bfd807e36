// The Python module `wetbrush`: a Session (core/session/session.h) with the same verbs as the CLI
// and the studio, stroke files and stroke samples from NumPy arrays, and the painting's maps as
// arrays (no copy: each array owns the image the core made). wb::Error becomes wetbrush.Error
// with the core's message. docs/PYTHON.md.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/brush/brush_spec.h"
#include "core/exec/device.h"
#include "core/exec/error.h"
#include "core/io/brush_json.h"
#include "core/io/png.h"
#include "core/io/stroke.h"
#include <nlohmann/json.hpp>
#include "core/params/param_table.h"
#include "core/render/camera.h"
#include "core/session/session.h"

namespace py = pybind11;
using namespace wb;

namespace {

Device device_of(const std::string& text) {
  Device d = Device::parse(text);
  d.activate();
  return d;
}

/// A NumPy array that owns `values` (moved, not copied) with the given shape.
template <class T>
py::array_t<T> owning_array(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* held = new std::vector<T>(std::move(values));
  py::capsule owner(held, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, held->data(), owner);
}

py::array_t<float> image_array(FloatImage&& f) {
  std::vector<py::ssize_t> shape{f.height, f.width};
  if (f.channels > 1) shape.push_back(f.channels);
  return owning_array(std::move(f.data), shape);
}

py::array_t<uint8_t> image_array(Image&& img) {
  return owning_array(std::move(img.rgba), {img.height, img.width, 4});
}

SimParams params_from_dict(const py::dict& params) {
  SimParams p;
  for (const auto& [k, v] : params) set_param(p, py::str(k), v.cast<double>());
  return p;
}

/// A 1-D float array of `n` values (or n = its length when n < 0), checked.
std::vector<double> column(const py::handle& obj, const char* name, py::ssize_t n) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || a.ndim() != 1) throw Error(std::string("paint: ") + name + " must be a 1-D array of numbers");
  if (n >= 0 && a.shape(0) != n)
    throw Error(std::string("paint: ") + name + " has " + std::to_string(a.shape(0)) + " values, x has " +
                std::to_string(n));
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

PaintLoad paint_of(const std::array<float, 3>& color, float oil, float load, bool reload) {
  PaintLoad p;
  for (int i = 0; i < 3; ++i) p.ryb[i] = color[i];
  p.oil = oil;
  p.load = load;
  p.reload_on_pen_down = reload;
  return p;
}

/// A stroke from sample arrays: canvas cells and seconds (t defaults to `rate` samples a second).
Stroke stroke_from_arrays(const CanvasDims& canvas, const BrushSpec& brush, const py::handle& x, const py::handle& y,
                          const py::handle& pressure, const py::object& t, double rate, const PaintLoad& paint,
                          const py::object& tilt_x, const py::object& tilt_y) {
  const std::vector<double> xs = column(x, "x", -1);
  const py::ssize_t n = py::ssize_t(xs.size());
  const std::vector<double> ys = column(y, "y", n), ps = column(pressure, "pressure", n);
  std::vector<double> ts(xs.size());
  if (t.is_none()) {
    if (!(std::isfinite(rate) && rate > 0.0)) throw Error("paint: rate must be a positive number of samples a second");
    for (size_t i = 0; i < ts.size(); ++i) ts[i] = double(i) / rate;
  } else {
    ts = column(t, "t", n);
  }
  const std::vector<double> tx = tilt_x.is_none() ? std::vector<double>(xs.size(), 0.0) : column(tilt_x, "tilt_x", n);
  const std::vector<double> ty = tilt_y.is_none() ? std::vector<double>(xs.size(), 0.0) : column(tilt_y, "tilt_y", n);
  Stroke s;
  s.canvas = canvas;
  s.brush = brush;
  s.paint = paint;
  s.source = "stroke from arrays";
  s.samples.resize(xs.size());
  for (size_t i = 0; i < xs.size(); ++i) {
    PenSample& q = s.samples[i];
    q.t = ts[i];
    q.x = float(xs[i]);
    q.y = float(ys[i]);
    q.pressure = float(ps[i]);
    q.tilt_x = float(tx[i]);
    q.tilt_y = float(ty[i]);
    q.down = ps[i] > 0.0;
  }
  validate_stroke(s);  // the file reader's checks: finite, in range, on the canvas, t increasing
  return s;
}

StrokeEvent event_of(StrokeEventKind kind) {
  StrokeEvent e;
  e.kind = kind;
  return e;
}

py::dict replay_report(Session& s) {
  const Replay& r = *s.replay();
  const Simulator& sim = s.sim();
  py::dict d;
  d["steps"] = r.steps_done();
  d["sim_time"] = r.sim_time();
  d["particles_max"] = sim.counters().particles_max;
  d["drift"] = sim.books().max_drift();
  d["nonfinite_events"] = sim.counters().nonfinite_events;
  return d;
}

py::dict run_replay(Session& s, const Stroke& stroke, const py::object& progress) {
  s.begin_replay(stroke);
  while (s.advance())
    if (!progress.is_none() && !progress(s.replay()->steps_done(), s.replay()->step_count()).cast<bool>())
      throw Error(stroke.source + ": replay cancelled");
  s.settle();
  return replay_report(s);
}

/// A brush from a shape's name (its default brush) or a dict of the stroke format's brush object.
BrushSpec brush_of(const py::object& brush) {
  if (py::isinstance<py::str>(brush)) return default_brush(brush_shape_from_string(brush.cast<std::string>()));
  if (!py::isinstance<py::dict>(brush)) throw Error("brush: give a shape's name or a dict of brush fields");
  const std::string text = py::module_::import("json").attr("dumps")(brush).cast<std::string>();
  return brush_from_json(nlohmann::json::parse(text), "brush", "");
}

SimConfig make_config(std::array<int, 3> canvas, const std::string& device, const py::object& brush,
                      std::optional<std::array<int, 3>> window, const py::dict& params, bool grid_only) {
  SimConfig c;
  c.device = device_of(device);
  c.canvas = CanvasDims{canvas[0], canvas[1], canvas[2]};
  c.brush = brush_of(brush);
  if (window) c.window = Int3{(*window)[0], (*window)[1], std::min((*window)[2], canvas[2])};
  c.window.z = std::min(c.window.z, canvas[2]);
  c.params = params_from_dict(params);
  c.particles = !grid_only;
  return c;
}

}  // namespace

PYBIND11_MODULE(wetbrush, m) {
  m.doc() = "wetbrush: bristle-level 3D oil-paint simulation (Chen, Kim, Ito, Wang 2015)";
  m.attr("__version__") = WB_VERSION;
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      error(e.what());
    }
  });

  m.def(
      "params",
      [] {
        py::list out;
        for (const ParamInfo& p : param_table()) {
          py::dict d;
          d["id"] = p.id, d["label"] = p.label, d["unit"] = p.unit, d["paper"] = p.paper, d["doc"] = p.tooltip;
          d["min"] = p.min, d["max"] = p.max, d["default"] = p.default_value();
          out.append(d);
        }
        return out;
      },
      "Every simulation parameter: id, label, unit, range, default and what it does.");

  m.def(
      "write_png",
      [](const std::string& path, const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& image) {
        if (image.ndim() != 3 || (image.shape(2) != 3 && image.shape(2) != 4))
          throw Error("write_png: the image must be an array of height x width x 3 or 4 bytes");
        write_png8(path, image.data(), int(image.shape(1)), int(image.shape(0)), int(image.shape(2)));
      },
      py::arg("path"), py::arg("image"), "Writes an RGB or RGBA8 array (render()) as PNG.");

  py::class_<Stroke>(m, "Stroke", "A stroke recording: pen samples, brush, paint and palette events.")
      .def_static(
          "from_arrays",
          [](std::array<int, 3> canvas, const py::handle& x, const py::handle& y, const py::handle& pressure,
             const py::object& t, double rate, const py::object& brush, std::array<float, 3> color, float oil,
             float load, const py::object& tilt_x, const py::object& tilt_y) {
            return stroke_from_arrays(CanvasDims{canvas[0], canvas[1], canvas[2]}, brush_of(brush), x, y, pressure, t,
                                      rate, paint_of(color, oil, load, true), tilt_x, tilt_y);
          },
          py::arg("canvas"), py::arg("x"), py::arg("y"), py::arg("pressure"), py::arg("t") = py::none(),
          py::arg("rate") = 200.0, py::arg("brush") = "round",
          py::arg("color") = std::array<float, 3>{0.9f, 0.1f, 0.05f}, py::arg("oil") = 0.3f, py::arg("load") = 1.f,
          py::arg("tilt_x") = py::none(), py::arg("tilt_y") = py::none(),
          "A stroke from sample arrays (canvas cells, seconds; pressure 0..1, 0 = pen up), checked as a file is.")
      .def_static(
          "load", [](const std::string& path) { return load_stroke(path); }, py::arg("path"),
          "Reads a stroke file (wetbrush JSON or a MyPaint event dump).")
      .def("save", [](const Stroke& s, const std::string& path) { save_stroke_json(s, path); }, py::arg("path"))
      .def_property_readonly("canvas", [](const Stroke& s) { return py::make_tuple(s.canvas.width, s.canvas.height, s.canvas.depth); })
      .def_property_readonly("duration", &Stroke::duration)
      .def_property_readonly("source", [](const Stroke& s) { return s.source; })
      .def_property_readonly("warnings", [](const Stroke& s) { return s.warnings; })
      .def_property_readonly("samples", [](const Stroke& s) {
        // t, x, y, pressure, tilt_x, tilt_y, twist, down: one row a sample.
        std::vector<double> v;
        v.reserve(s.samples.size() * 8);
        for (const PenSample& q : s.samples)
          for (double x : {q.t, double(q.x), double(q.y), double(q.pressure), double(q.tilt_x), double(q.tilt_y),
                           double(q.twist), q.down ? 1.0 : 0.0})
            v.push_back(x);
        return owning_array(std::move(v), {py::ssize_t(s.samples.size()), 8});
      });

  py::class_<Session>(m, "Session", "A painting: the simulator, its canvas, renderer and undo.")
      .def(py::init([](std::array<int, 3> canvas, const std::string& device, const py::object& brush,
                       std::optional<std::array<int, 3>> window, const py::dict& params, bool grid_only, int undo) {
             return std::make_unique<Session>(make_config(canvas, device, brush, window, params, grid_only), undo);
           }),
           py::arg("canvas") = std::array<int, 3>{512, 512, 32}, py::arg("device") = "auto",
           py::arg("brush") = "round", py::arg("window") = py::none(), py::arg("params") = py::dict(),
           py::arg("grid_only") = false, py::arg("undo") = 0,
           "A blank canvas (width, height, depth cells of 0.2 mm); brush: a shape's name (its default brush) or "
           "a dict of the stroke format's brush fields.")
      .def_static(
          "for_stroke",
          [](const Stroke& stroke, const std::string& device, const py::dict& params, bool grid_only,
             std::optional<std::array<int, 3>> window) {
            SimConfig c = stroke_config(stroke, device_of(device));
            if (window) c.window = Int3{(*window)[0], (*window)[1], std::min((*window)[2], c.canvas.depth)};
            for (const auto& [k, v] : params) set_param(c.params, py::str(k), v.cast<double>());
            c.particles = !grid_only;
            return std::make_unique<Session>(c, start_pose(stroke));
          },
          py::arg("stroke"), py::arg("device") = "auto", py::arg("params") = py::dict(), py::arg("grid_only") = false,
          py::arg("window") = py::none(),
          "A session set up as `wetbrush replay` sets one up for this stroke (canvas, brush, window).")
      .def_static(
          "open",
          [](const std::string& path, const std::string& device, int undo) {
            SimConfig base;
            base.device = device_of(device);
            Session::OpenOptions o;
            o.undo_levels = undo;
            return Session::open(path, base, o);
          },
          py::arg("path"), py::arg("device") = "auto", py::arg("undo") = 0, "Opens a painting (.ora).")
      .def_property_readonly("canvas", [](const Session& s) { return py::make_tuple(s.dims().width, s.dims().height, s.dims().depth); })
      .def_property_readonly("device", [](const Session& s) { return s.device().to_string(); })
      .def_property_readonly("brush", [](const Session& s) { return brush_to_json(s.config().brush).dump(); },
                             "The brush as JSON (the stroke format's brush object).")
      .def(
          "param",
          [](const Session& s, const std::string& id) {
            const ParamInfo* p = find_param(id);
            if (!p) throw Error("unknown parameter '" + id + "' (wetbrush.params() lists them)");
            return p->get(s.config().params);
          },
          py::arg("id"))
      .def(
          "set_params",
          [](Session& s, const py::dict& params) {
            SimConfig c = s.config();
            for (const auto& [k, v] : params) set_param(c.params, py::str(k), v.cast<double>());
            s.reconfigure(c);
          },
          py::arg("params"), "Sets parameters by id; the painting stays, the paint in flight settles.")
      .def(
          "replay",
          [](Session& s, const py::object& stroke, const py::object& progress) {
            const Stroke st = py::isinstance<Stroke>(stroke) ? stroke.cast<Stroke>() : load_stroke(py::str(stroke));
            return run_replay(s, st, progress);
          },
          py::arg("stroke"), py::arg("progress") = py::none(),
          "Replays a stroke (a Stroke or a file's path) on this canvas; progress(done, total) -> bool may cancel.")
      .def(
          "paint",
          [](Session& s, const py::handle& x, const py::handle& y, const py::handle& pressure, const py::object& t,
             double rate, std::array<float, 3> color, float oil, float load, const py::object& tilt_x,
             const py::object& tilt_y) {
            const Stroke st = stroke_from_arrays(s.dims(), s.config().brush, x, y, pressure, t, rate,
                                                 paint_of(color, oil, load, true), tilt_x, tilt_y);
            return run_replay(s, st, py::none());
          },
          py::arg("x"), py::arg("y"), py::arg("pressure"), py::arg("t") = py::none(), py::arg("rate") = 200.0,
          py::arg("color") = std::array<float, 3>{0.9f, 0.1f, 0.05f}, py::arg("oil") = 0.3f, py::arg("load") = 1.f,
          py::arg("tilt_x") = py::none(), py::arg("tilt_y") = py::none(),
          "Paints one stroke from sample arrays (canvas cells; t in seconds, else `rate` samples a second; "
          "pressure 0..1, 0 = pen up); the brush is loaded with `color` (RYB) at pen-down.")
      .def("undo", [](Session& s) { return s.undo().has_value(); }, "Undoes the last stroke (False: none).")
      .def("redo", [](Session& s) { return s.redo().has_value(); }, "Redoes the last undone stroke (False: none).")
      .def("height", [](Session& s) { return image_array(s.height_map()); }, "Surface height a cell, cells (0.2 mm).")
      .def("normal", [](Session& s) { return image_array(s.normal_map()); }, "Unit surface normal a cell (x, y, z).")
      .def("albedo", [](Session& s) { return image_array(s.albedo()); }, "Unlit paint colour a cell, linear RGB.")
      .def(
          "render",
          [](Session& s, const std::string& camera, std::optional<std::array<float, 4>> region, float zoom) {
            if (camera != "top" && camera != "oblique") throw Error("render: camera must be 'top' or 'oblique'");
            if (!(std::isfinite(zoom) && zoom > 0.f && zoom <= 16.f)) throw Error("render: zoom must be in (0, 16]");
            if (camera == "oblique") return image_array(s.render(Camera::oblique(s.dims(), 30.f, zoom)));
            const CanvasDims d = s.dims();
            if (!region)
              return image_array(s.render(Camera::top_region(0.f, 0.f, float(d.width), float(d.height), zoom)));
            const auto& r = *region;
            if (!(std::isfinite(r[0]) && std::isfinite(r[1]) && r[2] >= 1.f && r[3] >= 1.f && r[2] * zoom <= 16384.f &&
                  r[3] * zoom <= 16384.f))
              throw Error(
                  "render: region is (x0, y0, width, height) in cells, at least a cell and at most 16384 pixels a "
                  "side");
            return image_array(s.render(Camera::top_region(r[0], r[1], r[2], r[3], zoom)));
          },
          py::arg("camera") = "top", py::arg("region") = py::none(), py::arg("zoom") = 1.f,
          "The painting lit as the studio shows it, RGBA8: from above (a region (x0, y0, width, height) in "
          "cells, zoom pixels a cell) or oblique.")
      .def(
          "dip",
          [](Session& s, std::array<float, 3> color, float oil, float load) {
            StrokeEvent e = event_of(StrokeEventKind::Dip);
            for (int i = 0; i < 3; ++i) e.ryb[i] = color[i];
            e.oil = oil, e.load = load;
            s.apply(e);
          },
          py::arg("color"), py::arg("oil") = 0.3f, py::arg("load") = 1.f,
          "Dips the brush into a well of this paint (RYB), up to `load` of its capacity.")
      .def(
          "wipe",
          [](Session& s, float fraction) {
            StrokeEvent e = event_of(StrokeEventKind::Wipe);
            e.fraction = fraction;
            s.apply(e);
          },
          py::arg("fraction") = 0.5f, "Wipes this fraction of its paint off the brush.")
      .def(
          "clean",
          [](Session& s) { s.apply(event_of(StrokeEventKind::Clean)); },
          "Cleans the brush in solvent.")
      .def(
          "dry",
          [](Session& s) { s.apply(event_of(StrokeEventKind::Dry)); },
          "Lets the painting dry: every painted cell becomes solid (the undo history starts again).")
      .def(
          "lay_ground",
          [](Session& s, const py::dict& ground) {
            const std::string text = py::module_::import("json").attr("dumps")(ground).cast<std::string>();
            s.lay_ground(ground_from_json(nlohmann::json::parse(text), "ground", ""));
          },
          py::arg("ground"),
          "Primes the blank canvas with a woven ground: {'weave': 'linen' or 'cotton_duck', 'thread_mm', "
          "'relief_mm', 'priming_mm'} (the stroke format's canvas.ground).")
      .def(
          "pick",
          [](Session& s, int x, int y) -> py::object {
            const std::optional<Vec3> v = s.pick(x, y);
            if (!v) return py::none();
            return py::make_tuple(v->x, v->y, v->z);
          },
          py::arg("x"), py::arg("y"), "The pigment (RYB) at a cell, None where the canvas is bare.")
      .def(
          "put_paint",
          [](Session& s, float x, float y, float radius, float height, std::array<float, 3> color, float oil) {
            s.put_paint(x, y, radius, height, paint_of(color, oil, 1.f, true));
          },
          py::arg("x"), py::arg("y"), py::arg("radius"), py::arg("height"), py::arg("color"), py::arg("oil") = 0.3f,
          "Puts out a dome of fresh paint (cells), as on a palette.")
      .def("save", [](Session& s, const std::string& path) { s.save(path, {{"generator", "wetbrush python"}}); },
           py::arg("path"), "Saves the painting (.ora with its paint volume), atomically.")
      .def(
          "export_maps",
          [](Session& s, const std::string& height, const std::string& normal, const std::string& albedo) {
            if (height.empty() && normal.empty() && albedo.empty())
              throw Error("export_maps: nothing to do: give height, normal and/or albedo");
            return s.export_maps(MaterialMapPaths{height, normal, albedo});
          },
          py::arg("height") = "", py::arg("normal") = "", py::arg("albedo") = "",
          "Writes the material maps as PNG (as `wetbrush export`); returns the height units a cell.")
      .def(
          "census",
          [](Session& s) {
            const PaintCensus c = s.sim().census();
            py::dict d;
            d["bristles"] = c.bristles, d["particles"] = c.particles, d["grid"] = c.grid, d["total"] = c.total();
            return d;
          },
          "Where the paint is now, kg.");
}
