// Grid stage drivers (paper §4.2, Algorithm 1), compiled once per backend from this
// source (grid_cpu.cpp, grid_cuda.cu). Each function is one or two launches over
// cells or faces; the physics is in advect_/viscosity_/project_kernels.h.
#pragma once
#include "core/color/ryb.h"
#include "core/exec/atomics.h"
#include "core/exec/parallel_for.h"
#include "core/grid/advect_kernels.h"
#include "core/grid/grid.h"
#include "core/grid/project_kernels.h"
#include "core/grid/rheology.h"
#include "core/grid/viscosity_kernels.h"

namespace wb::WB_BACKEND_NS {

namespace detail {
WB_HD WB_INLINE int64_t all_faces(const GridDims& d) { return d.nu() + d.nv() + d.nw(); }
/// Face t of the faces of the cells below `layers` (faces_below) as one list u | v | w: its
/// component c and index f within it (layers = nz: every face).
WB_HD WB_INLINE void split_face_below(const GridDims& d, int layers, int64_t t, int& c, int64_t& f) {
  const int64_t nu = int64_t(d.nx + 1) * d.ny * layers, nv = int64_t(d.nx) * (d.ny + 1) * layers;
  if (t < nu) {
    c = 0;
    f = t;
  } else if (t < nu + nv) {
    c = 1;
    f = t - nu;
  } else {
    c = 2;
    f = t - nu - nv;
  }
}
template <class F>
struct CellsIn {
  GridDims d;
  const GridExtent* e;
  F fn;
  WB_HD void operator()(int64_t t) const {
    const int64_t c = extent_cell(d, *e, t);
    int i, j, k;
    d.decompose_cell(c, i, j, k);  // a kernel that does not use them drops the division
    fn(c, i, j, k);
  }
};
template <class F>
struct AllCells {
  GridDims d;
  F fn;
  WB_HD void operator()(int64_t c) const {
    int i, j, k;
    d.decompose_cell(c, i, j, k);
    fn(c, i, j, k);
  }
};
template <class F>
struct FacesIn {
  GridDims d;
  const GridExtent* e;
  F fn;
  WB_HD void operator()(int64_t t) const {
    int c, i, j, k;
    int64_t f;
    extent_face(d, *e, t, c, f);
    d.decompose_face(c, f, i, j, k);  // a kernel that does not use them drops the division
    fn(c, f, i, j, k);
  }
};
template <class F>
struct AllFaces {
  GridDims d;
  F fn;
  WB_HD void operator()(int64_t t) const {
    int c, i, j, k;
    int64_t f;
    split_face_below(d, d.nz, t, c, f);
    d.decompose_face(c, f, i, j, k);
    fn(c, f, i, j, k);
  }
};
}  // namespace detail

/// fn(c, i, j, k) for the first *count cells of the extent e (x fastest, then y, then z). CUDA
/// launches a thread a cell that finds its cell by division; the CPU backend, whose device memory
/// is the host's, reads the extent and walks it a row along x at a time (one division a row).
template <class F>
void for_extent_cells(const GridDims& d, const GridExtent* e, const int64_t* count, F fn) {
#if defined(__CUDACC__)
  parallel_for_count(count, d.cells(), detail::CellsIn<F>{d, e, fn});
#else
  const GridExtent x = *e;
  const int64_t bx = x.x1 - x.x0, by = x.y1 - x.y0;
  if (bx <= 0 || by <= 0) return;
  const int64_t rows = (*count < d.cells() ? *count : d.cells()) / bx;
  parallel_for(
      rows,
      [=](int64_t r) {
        const int k = int(r / by), j = int(x.y0 + r % by);
        const int64_t c0 = (int64_t(k) * d.ny + j) * d.nx + x.x0;
        for (int64_t i = 0; i < bx; ++i) fn(c0 + i, int(x.x0 + i), j, k);
      },
      kMinParallelSize / bx + 1);
#endif
}
/// fn(c, i, j, k) for every cell a stage visits: the extent's, or all.
template <class F>
void for_cells(const GridDims& d, const GridExtent* e, F fn) {
  if (e) {
    for_extent_cells(d, e, &e->cells, fn);
    return;
  }
  parallel_for(d.cells(), detail::AllCells<F>{d, fn});
}
/// fn(c, f, i, j, k) (component, index, and the face's (i, j, k) of face_position) for every face
/// a stage visits: those of the extent's cells, or all. On the CPU backend a row along x at a time,
/// as for_extent_cells: the row gives j and k, no division a face.
template <class F>
void for_faces(const GridDims& d, const GridExtent* e, F fn) {
  if (!e) {
    parallel_for(detail::all_faces(d), detail::AllFaces<F>{d, fn});
    return;
  }
#if defined(__CUDACC__)
  parallel_for_count(&e->faces, detail::all_faces(d), detail::FacesIn<F>{d, e, fn});
#else
  const GridExtent x = *e;
  const int64_t bx = x.x1 - x.x0, by = x.y1 - x.y0, layers = x.layers;
  if (bx <= 0 || by <= 0) return;
  // Rows of u (bx + 1 faces each), of v and of w (bx each), as extent_face numbers them.
  const int64_t ru = by * layers, rv = (by + 1) * layers;
  const int64_t faces = x.faces < detail::all_faces(d) ? x.faces : detail::all_faces(d);
  const int64_t rw = (faces - (bx + 1) * ru - bx * rv) / bx;
  parallel_for(
      ru + rv + rw,
      [=](int64_t r) {
        const int c = r < ru ? 0 : (r < ru + rv ? 1 : 2);
        const int64_t s = c == 0 ? r : (c == 1 ? r - ru : r - ru - rv), ey = by + (c == 1), ex = bx + (c == 0);
        const int k = int(s / ey), j = int(x.y0 + s % ey);
        const int64_t f0 = (int64_t(k) * (d.ny + (c == 1)) + j) * (d.nx + (c == 0)) + x.x0;
        for (int64_t i = 0; i < ex; ++i) fn(c, f0 + i, int(x.x0 + i), j, k);
      },
      kMinParallelSize / bx + 1);
#endif
}

void grid_classify(GridView g, PaintWindowView pw, BristleField br, const float* particle_density, CanvasDims canvas,
                   FlowColumns flow, float liquid_threshold, float dry_threshold) {
  const int canvas_w = canvas.width, canvas_h = canvas.height, canvas_d = canvas.depth;
  const GridDims d = g.d;
  const auto cell = [=] WB_HD(int64_t c, int i, int j, int k) {
    const int cx = i + pw.ox, cy = j + pw.oy, cz = k + pw.oz;
    const bool on =
        cx >= 0 && cy >= 0 && cz >= 0 && cx < canvas_w && cy < canvas_h && cz < canvas_d && flow.contains(cx, cy);
    // Joint density (§4.3): the particles' rasterised volume counts as liquid too.
    const float joint = pw.density[c] + (particle_density ? particle_density[c] : 0.f);
    g.cls[c] = classify_cell(joint, pw.dryness[c], on, liquid_threshold, dry_threshold);
  };
  // The extent's cells and the layer above them: the faces on top read its class.
  if (g.extent)
    for_extent_cells(d, g.extent, &g.extent->classes, cell);
  else
    for_cells(d, nullptr, cell);
  // Open fraction, solid velocity and fluid flag of each face in one pass: the flag reads only
  // the face's own fraction and its two cells' classes.
  for_faces(d, g.extent, [=] WB_HD(int c, int64_t f, int i, int j, int k) {
    float theta, us;
    face_fraction(d, g.cls, br, c, i, j, k, theta, us);
    g.theta[c][f] = theta;
    g.solid_vel[c][f] = us;
    g.fluid[c][f] = face_is_fluid(d, g.cls, g.theta[c], c, i, j, k) ? 1 : 0;
  });
}

void grid_column_tops(GridDims d, const float* rho, const float* dryness, float dry_threshold,
                      const float* particle_density, float trace, float* out) {
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_for_runs<kColumnLanes>(n, [=] WB_HD(int64_t col0, int lanes) {
    // The column's top layer (k + 1) holding paint above `trace`, and holding paint or particles;
    // where it holds either, its x, -x, y and -y, whose maxima are the box of such columns. Dried
    // paint counts unless it is solid (dried_solid): a canvas's ground or a dried layer is solid,
    // never moves, and the cells of it that wet paint can reach lie within the box's margins; a
    // dried trace thinner than half a cell is no solid (wet paint that reaches it mixes with it)
    // and the passes bounded by the extent must see it. Each layer of the run's columns at once,
    // down the whole column (parallel_for_runs<kColumnLanes>).
    // Without particles the paint's density stands in for theirs against a bound none passes, so
    // that every lane does the same loads and compares (no branch: the run vectorises).
    const float* pd = particle_density ? particle_density : rho;
    const float pd_trace = particle_density ? trace : INFINITY;
    float top[kColumnLanes], joint[kColumnLanes];
    for (int l = 0; l < lanes; ++l) top[l] = joint[l] = 0.f;
    for (int k = d.nz - 1; k >= 0; --k) {
      const int64_t c0 = int64_t(k) * n + col0;
      const float level = float(k + 1);
      for (int l = 0; l < lanes; ++l) {
        const int64_t c = c0 + l;
        const float r = rho[c], dr = dryness[c];
        const bool wet = (r > trace) & !dried_solid(r, dr, dry_threshold);
        const bool held = wet | (pd[c] > pd_trace);
        top[l] = (top[l] == 0.f) & wet ? level : top[l];
        joint[l] = (joint[l] == 0.f) & held ? level : joint[l];
      }
    }
    for (int l = 0; l < lanes; ++l) {
      const int64_t col = col0 + l;
      const float none = -INFINITY, i = float(col % d.nx), j = float(col / d.nx);
      out[col] = top[l];
      out[n + col] = joint[l];
      out[2 * n + col] = joint[l] > 0.f ? i : none;
      out[3 * n + col] = joint[l] > 0.f ? -i : none;
      out[4 * n + col] = joint[l] > 0.f ? j : none;
      out[5 * n + col] = joint[l] > 0.f ? -j : none;
    }
  });
}

void grid_running_columns(GridView g, PaintWindowView pw, float dry_threshold, float speed, float* out) {
  // A column runs where a cell of wet paint has a face across the canvas (u or v) faster than
  // `speed`: paint sinking as it settles (w) does not run. Its x, -x, y, -y (canvas cells, the
  // column's centre) for the maxima that make the box of such columns. Each layer of the run's
  // columns at once (parallel_for_runs<kColumnLanes>); the faces only of a layer with wet paint.
  const GridDims d = g.d;
  const int64_t n = int64_t(d.nx) * d.ny, u_layer = int64_t(d.ny) * (d.nx + 1), v_layer = int64_t(d.ny + 1) * d.nx;
  parallel_for_runs<kColumnLanes>(n, [=] WB_HD(int64_t col0, int lanes) {
    int64_t u0[kColumnLanes], v0[kColumnLanes];  // the lane's u and v faces in layer 0
    bool running[kColumnLanes];
    for (int l = 0; l < lanes; ++l) {
      const int64_t col = col0 + l, i = col % d.nx, j = col / d.nx;
      u0[l] = j * (d.nx + 1) + i;
      v0[l] = j * d.nx + i;
      running[l] = false;
    }
    for (int k = 0; k < d.nz; ++k) {
      const int64_t c0 = int64_t(k) * n + col0, uk = int64_t(k) * u_layer, vk = int64_t(k) * v_layer;
      bool wet[kColumnLanes], any = false;
      for (int l = 0; l < lanes; ++l) {
        wet[l] = (pw.density[c0 + l] > 0.f) & !(pw.dryness[c0 + l] >= dry_threshold);
        any = any | wet[l];
      }
      if (!any) continue;  // most layers: the faces are not read
      for (int l = 0; l < lanes; ++l) {
        const int64_t ui = uk + u0[l], vi = vk + v0[l];
        const float u = maxf(fabsf(g.vel[0][ui]), fabsf(g.vel[0][ui + 1]));
        const float v = maxf(fabsf(g.vel[1][vi]), fabsf(g.vel[1][vi + d.nx]));
        running[l] = running[l] | (wet[l] & (maxf(u, v) > speed));
      }
    }
    for (int l = 0; l < lanes; ++l) {
      const int64_t col = col0 + l;
      const float none = -INFINITY, x = float(col % d.nx + pw.ox) + 0.5f, y = float(col / d.nx + pw.oy) + 0.5f;
      out[col] = running[l] ? x : none;
      out[n + col] = running[l] ? -x : none;
      out[2 * n + col] = running[l] ? y : none;
      out[3 * n + col] = running[l] ? -y : none;
    }
  });
}

void grid_first_extent(GridDims d, const float* maxima, GridExtent* e, float* rates) {
  parallel_for(1, [=] WB_HD(int64_t) {
    for (int a = 0; a < 3; ++a) rates[a] = 0.f;  // grid_paint_outflow's maxima start here
    // The cells holding paint or particles and a cell around them: the faces of their cells
    // carry the outflow.
    const float top = maxf(maxima[0], 0.f);
    int box[4];
    column_box(d, maxima + 1, 1, box);
    set_extent(*e, d, top < float(d.nz) ? int(top) : d.nz, box[0], box[1], box[2], box[3]);
  });
}

void grid_advect_plan(GridDims d, const float* rates, const float* paint_top, const float* joint, float dt,
                      AdvectPlan* plan, GridExtent* e) {
  parallel_for(1, [=] WB_HD(int64_t) {
    // The paint's reach along each axis, cells: the most a painted cell's face carries in the
    // step, rounded up, and the cell the last part comes from. None where no painted cell's face
    // carries flow along the axis: its pass writes nothing.
    AdvectPlan p{};
    const float longest = float(imax(imax(d.nx, d.ny), d.nz));
    for (int a = 0; a < 3; ++a) {
      const float c = isfinite(rates[a]) ? minf(maxf(rates[a] * dt, 0.f), longest) : 0.f;
      p.reach[a] = c > 0.f ? int(ceilf(c)) + 1 : 0;
      p.courant = maxf(p.courant, c);
      p.passes += p.reach[a] > 0;
    }
    const int top = int(minf(maxf(*paint_top, 0.f), float(d.nz)));
    const int joint_top = int(minf(maxf(joint[0], 0.f), float(d.nz)));
    // The velocity's layers: the paint's and particles', risen by the paint's reach up, and the
    // stencils that reach them. Across, the paint's and particles' columns, as far as the paint
    // reaches along x and y, and the stencils' two cells beyond: the box whose faces the paint's
    // passes read, and which bounds their walks.
    const int across = imax(p.reach[0], p.reach[1]);
    int box[4];
    column_box(d, joint + 1, across + 2, box);
    GridExtent x{};
    set_extent(x, d, imin(d.nz, joint_top + p.reach[2] + 2), box[0], box[1], box[2], box[3]);
    *e = x;
    // The paint's passes (Grid::advect_paint): in them the paint moves at most reach[a] cells
    // along a, so no cell farther from it (in tiles, and above top + reach[z]) computes a flux.
    // Their walks read at most reach[a] cells beyond a cell they advect, and the last one's
    // upwind neighbour: the ring of halo tiles and the layers above.
    p.top = top;
    p.layers = imin(d.nz, top + p.reach[2]);
    p.deep = imin(d.nz, p.layers + p.reach[2] + 1);
    p.reach_tiles = (across + kPaintTile - 1) / kPaintTile;
    p.halo_tiles = imax(1, (across + 1 + kPaintTile - 1) / kPaintTile);
    *plan = p;
  });
}

void grid_paint_outflow(GridView g, const float* rho, float* rates) {
  // The largest outflow rate along each axis of a painted cell, into rates[0..3) (atomic maxima:
  // the same whatever the order). The painted cells lie in the step's first extent, which g's
  // extent is (grid_first_extent).
  const GridDims d = g.d;
  for_cells(d, g.extent, [=] WB_HD(int64_t c, int i, int j, int k) {
    // Traces (a millionth of a cell) do not count. The donor limit leaves a part in 10^6 of what
    // a cell held, so a drained cell in the bristles' fast flow keeps 1e-6, then 1e-12, ... of a
    // cell: sized by them, the studio's stroke took 16 sub-steps a step where its paint needed 3.
    // A trace asked for more than it holds gives what it holds (the donor limit).
    if (!(rho[c] > kTraceDensity)) return;
    for (int a = 0; a < 3; ++a) {
      const float r = cell_axis_outflow(g, rho, a, i, j, k);
      if (r > 0.f) atomic_max(&rates[a], r);  // loads first, and writes only a larger value
    }
  });
}

namespace detail {
/// Row q of the tiles in `list`, *layers deep: each element is a row of kPaintTile cells along x
/// (tile-major, then k, then the tile's rows), so the index arithmetic is paid once a row and the
/// row's cells are contiguous. fn(t, c) for each of its cells inside the window (t its tile);
/// with `process`, only in the tiles it flags; with `below`, only in the layers under *below +
/// *rise. The depths are the step's plan's, on the device.
template <class F>
struct TileCells {
  GridDims d;
  const int32_t* list;
  int tiles_x;
  const int32_t* layers;
  F fn;
  const int32_t* process = nullptr;
  const int32_t* below = nullptr;
  const int32_t* rise = nullptr;
  WB_HD void operator()(int64_t q) const {
    const uint32_t per_tile = uint32_t(kPaintTile) * uint32_t(*layers), e = uint32_t(q);
    const int32_t t = list[e / per_tile];
    if (process && !process[t]) return;
    const uint32_t r = e % per_tile;
    const int k = int(r / kPaintTile), j = (t / tiles_x) * kPaintTile + int(r % kPaintTile);
    if (j >= d.ny || (below && k >= *below + (rise ? *rise : 0))) return;
    const int i0 = (t % tiles_x) * kPaintTile, i1 = i0 + kPaintTile < d.nx ? i0 + kPaintTile : d.nx;
    const int64_t row = d.cell(0, j, k);
    for (int i = i0; i < i1; ++i) fn(t, row + i);
  }
};
}  // namespace detail

void grid_paint_tiles(GridDims d, const float* rho, const float* dryness, float dry_threshold, const AdvectPlan* plan,
                      int32_t* mark, int32_t* active, int32_t* halo, int64_t* counts, int32_t* below) {
  const int tx = (d.nx + kPaintTile - 1) / kPaintTile, ty = (d.ny + kPaintTile - 1) / kPaintTile;
  parallel_for(
      int64_t(tx) * ty,
      [=] WB_HD(int64_t t) {
        const int i0 = int(t % tx) * kPaintTile, j0 = int(t / tx) * kPaintTile, layers = plan->layers;
        int32_t any = 0;
        // Paint that can move: dried solid paint (a canvas's ground, a dried layer) stays put.
        for (int k = 0; k < layers && !any; ++k)
          for (int j = j0; j < j0 + kPaintTile && j < d.ny && !any; ++j)
            for (int i = i0; i < i0 + kPaintTile && i < d.nx; ++i) {
              const int64_t c = d.cell(i, j, k);
              if (rho[c] > 0.f && !dried_solid(rho[c], dryness[c], dry_threshold)) {
                any = 1;
                break;
              }
            }
        mark[t] = any;
      },
      1);
  // A tile within the plan's reach_tiles of paint is advected; the ring of halo_tiles beyond it
  // is the halo the advected cells read (their faces' walks and the last cell's slope).
  parallel_for(
      int64_t(tx) * ty,
      [=] WB_HD(int64_t t) {
        const int reach = plan->reach_tiles, x = int(t % tx), y = int(t / tx), far = reach + plan->halo_tiles;
        int best = far + 1;
        for (int b = y - far; b <= y + far; ++b)
          for (int a = x - far; a <= x + far; ++a) {
            if (a < 0 || b < 0 || a >= tx || b >= ty || !mark[int64_t(b) * tx + a]) continue;
            const int dx = a > x ? a - x : x - a, dy = b > y ? b - y : y - b;
            const int dist = dx > dy ? dx : dy;
            best = best < dist ? best : dist;
          }
        if (best <= reach)
          active[atomic_add(&counts[0], int64_t(1))] = int32_t(t);
        else if (best <= far)
          halo[atomic_add(&counts[1], int64_t(1))] = int32_t(t);
      },
      1);
  parallel_for(1, [=] WB_HD(int64_t) {
    counts[2] = counts[0] * kPaintTile * plan->layers;  // rows of kPaintTile cells (TileCells)
    counts[3] = counts[0] * kPaintTile * plan->deep;
    counts[4] = counts[1] * kPaintTile * plan->deep;
    *below = plan->top;  // the layers holding paint before the first pass
  });
}

void grid_copy_paint_tiles(GridDims d, PaintTiles tiles, PaintWindowView src, PaintWindowView dst, TileCopy what) {
  const AdvectPlan* plan = tiles.plan;
  const bool reads = what == TileCopy::kIntoScratch;
  auto copy = [=] WB_HD(int32_t, int64_t c) {
    if (!reads && plan->passes % 2 == 0) return;  // an even number left the result in the paint
#define WB_X(name, doc) dst.name[c] = src.name[c];
    WB_PAINT_FIELDS(WB_X)
#undef WB_X
  };
  using Rows = detail::TileCells<decltype(copy)>;
  const int32_t* deep = &tiles.plan->deep;
  parallel_for_count(tiles.counts + (reads ? 3 : 2), tiles.capacity,
                     Rows{d, tiles.active, tiles.tiles_x, reads ? deep : &tiles.plan->layers, copy});
  if (reads) parallel_for_count(tiles.counts + 4, tiles.capacity, Rows{d, tiles.halo, tiles.tiles_x, deep, copy});
}

void grid_paint_tiles_pass(GridDims d, PaintTiles tiles, const int32_t* before, int axis, int32_t* process,
                           int32_t* after) {
  // A pass along an axis moves paint only along it, at most its reach in tiles: a tile with no
  // paint that far along the axis (after the last pass; before the first: the paint's) gets
  // none and gives none. It is skipped when no pass of the step has visited it either: then the
  // buffer it would write holds its cells already (the scratch copy's, or those of two passes
  // ago, which the pass between left unchanged). So the flags gather over the step's passes.
  const int tx = tiles.tiles_x, ty = (d.ny + kPaintTile - 1) / kPaintTile;
  const int32_t* active = tiles.active;
  const AdvectPlan* plan = tiles.plan;
  parallel_for_count(tiles.counts, tiles.capacity, [=] WB_HD(int64_t slot) {
    const int32_t t = active[slot];
    if (plan->reach[axis] == 0) {
      after[t] = before[t];  // no flow along the axis: the pass moves nothing, and visits nothing
      return;
    }
    const int x = t % tx, y = t / tx, reach_tiles = (plan->reach[axis] + kPaintTile - 1) / kPaintTile;
    const int rx = axis == 0 ? reach_tiles : 0, ry = axis == 1 ? reach_tiles : 0;
    int32_t busy = process[t];
    for (int b = y - ry; b <= y + ry && !busy; ++b)
      for (int a = x - rx; a <= x + rx; ++a)
        if (a >= 0 && b >= 0 && a < tx && b < ty && before[b * tx + a]) {
          busy = 1;
          break;
        }
    process[t] = busy;
  });
}

void grid_advect_paint_axis(GridView g, PaintWindowView paint, PaintWindowView scratch, int axis, int pass, int order,
                            float dt, float dry_threshold, PaintTiles tiles, const int32_t* process, int32_t* painted,
                            const int32_t* below, int32_t* below_next) {
  WB_REQUIRE(g.extent, "grid advection: the paint's box is not set");
  const GridDims d = g.d;
  const GridExtent* box = g.extent;
  const AdvectPlan* plan = tiles.plan;
  const int32_t* reach_at = &plan->reach[axis];
  auto cell = [=] WB_HD(int32_t t, int64_t c) {
    const int reach = *reach_at;
    if (reach == 0) return;  // no flow along the axis: the next pass reads where this one would have
    // The buffers alternate with the passes that move paint (advect_in_scratch).
    const bool flip = advect_in_scratch(*plan, order, pass);
    const PaintWindowView& src = flip ? scratch : paint;
    const PaintWindowView& dst = flip ? paint : scratch;
    int i, j, k;
    d.decompose_cell(c, i, j, k);
    // The cells whose faces were classified this step: paint moves within them (Grid::advect).
    const bool inside = i >= box->x0 && i < box->x1 && j >= box->y0 && j < box->y1 && k < box->layers;
    const int lo = axis == 0 ? box->x0 : (axis == 1 ? box->y0 : 0);
    const int hi = axis == 0 ? box->x1 : (axis == 1 ? box->y1 : box->layers);
    const int64_t stride = axis == 0 ? 1 : (axis == 1 ? int64_t(d.nx) : int64_t(d.nx) * d.ny);
    const int at = axis == 0 ? i : (axis == 1 ? j : k);
    // A pass along z may change every layer it visits: the passes after it visit them too, so
    // that none is left with what the buffer held two passes ago.
    if (axis == 2 && k + 1 > atomic_load(below_next)) atomic_max(below_next, k + 1);
    // Air stays air: no walk of the cell's faces can reach paint when none lies within the reach.
    bool near = false;
    for (int o = -reach; o <= reach && inside && !near; ++o)
      near = at + o >= lo && at + o < hi && src.density[c + o * stride] != 0.f;
    if (!near) {
#define WB_X(name, doc) dst.name[c] = src.name[c];
      WB_PAINT_FIELDS(WB_X)
#undef WB_X
      return;
    }
    // In through the low face, out through the high one (signed): the same face flux is
    // computed, bit for bit, by the two cells it joins, so what one loses the other gains.
    const FaceCarry in = face_paint_carry(g, src, axis, i, j, k, dt, reach, lo, hi);
    const FaceCarry out =
        face_paint_carry(g, src, axis, i + (axis == 0), j + (axis == 1), k + (axis == 2), dt, reach, lo, hi);
    const float rho = src.density[c];
    // The paths of the two faces bound the interval the cell's paint comes from, so the sum is
    // >= 0 but for the round-off of the three terms (a few ulps of the larger flux): cut to 0.
    const float rho_new = maxf(add_rn(rho, sub_rn(in.m, out.m)), 0.f);
    dst.density[c] = rho_new;
    const float dry_new =
        rho_new > 1e-12f ? add_rn(rho * src.dryness[c], sub_rn(in.dry, out.dry)) / rho_new : src.dryness[c];
    if (rho_new > 0.f && !dried_solid(rho_new, dry_new, dry_threshold)) {
      // Paint that can move: the next passes visit this tile's neighbours and this layer.
      if (!atomic_load(&painted[t])) atomic_or(&painted[t], 1);
      if (k + 1 > atomic_load(below_next)) atomic_max(below_next, k + 1);
    }
    // Pigment, oil and dryness travel with the paint (mass-weighted), so each stays a convex mix
    // of what met in the cell.
    auto carry = [&](const float* q, float q_in, float q_out, float* to) {
      to[c] = rho_new > 1e-12f ? add_rn(rho * q[c], sub_rn(q_in, q_out)) / rho_new : q[c];
    };
    static_assert(kPaintFieldCount == 6, "advect every paint field");
    carry(src.pigment_r, in.r, out.r, dst.pigment_r);
    carry(src.pigment_y, in.y, out.y, dst.pigment_y);
    carry(src.pigment_b, in.b, out.b, dst.pigment_b);
    carry(src.oil, in.oil, out.oil, dst.oil);
    dst.dryness[c] = dry_new;
  };
  // A pass along z lifts paint at most its reach in layers above those holding it.
  parallel_for_count(tiles.counts + 2, tiles.capacity,
                     detail::TileCells<decltype(cell)>{d, tiles.active, tiles.tiles_x, &tiles.plan->layers, cell,
                                                       process, below, axis == 2 ? reach_at : nullptr});
}

void grid_advect_velocity(GridView g, const float* u, const float* v, const float* w, float dt) {
  WB_REQUIRE(g.extent, "grid advection: the velocity's extent is not set");
  const GridDims d = g.d;
  for_faces(d, g.extent, [=] WB_HD(int c, int64_t f, int i, int j, int k) {
    if (g.theta[c][f] <= 0.f) {
      g.vel[c][f] = g.solid_vel[c][f];
      return;
    }
    // An air face keeps the velocity the last projection extrapolated to it (docs/GRID.md
    // "Advection and mass": the paint's momentum is carried where the paint is).
    if (!g.fluid[c][f]) return;
    const Vec3 p = backtrace(u, v, w, d, face_position(c, i, j, k), dt);
    g.vel[c][f] = sample_component(c == 0 ? u : (c == 1 ? v : w), d, c, p);
  });
}

void grid_gravity(GridView g, float* ph, float g_dt, float g_dt_y) {
  const GridDims d = g.d;
  // Hydrostatic head of each liquid cell: contiguous liquid cells from it to the surface.
  const GridExtent* e = g.extent;
  parallel_for(int64_t(d.nx) * d.ny, [=] WB_HD(int64_t col) {
    const int i = int(col % d.nx), j = int(col / d.nx);
    if (e && (i < e->x0 || i >= e->x1 || j < e->y0 || j >= e->y1)) return;
    float head = 0.f;
    for (int k = (e ? e->layers : d.nz) - 1; k >= 0; --k) {
      const int64_t c = d.cell(i, j, k);
      head = g.cls[c] == kCellLiquid ? head + g_dt : 0.f;
      ph[c] = head;
    }
  });
  for_faces(d, g.extent, [=] WB_HD(int c, int64_t f, int i, int j, int k) {
    if (g.theta[c][f] <= 0.f) return;
    int64_t a, b;
    bool ha, hb;
    face_cells(d, c, i, j, k, a, b, ha, hb);
    const bool la = ha && g.cls[a] == kCellLiquid, lb = hb && g.cls[b] == kCellLiquid;
    if (!la && !lb) return;
    g.vel[c][f] += gravity_face_impulse(c, la, lb, la ? ph[a] : 0.f, lb ? ph[b] : 0.f, g_dt, g_dt_y);
  });
}

// --- thin films (docs/GRID.md "Thin films") --------------------------------------------------

/// Column c's tau_y and K at its oil, kept beside it (kFilmTau, kFilmK).
WB_HD WB_INLINE void film_rheology(float* col, int64_t n, int64_t c, const FilmFlow& f) {
  const HerschelBulkley hb = rheology_at_oil(col[kFilmOil * n + c], f.stiff, f.oily);
  col[kFilmTau * n + c] = hb.tau_y, col[kFilmK * n + c] = hb.K;
}

void grid_film_columns(GridDims d, const GridExtent* e, PaintWindowView pw, BristleField br,
                       const float* particle_density, FlowColumns flow, float dry_threshold, float film_max,
                       FilmFlow f, float* col) {
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_for_runs<kColumnLanes>(n, [=] WB_HD(int64_t c0, int lanes) {
    // Columns outside the paint's box (no paint there) or the flow's (a wall: FlowColumns) are no
    // film; a run with none inside reads no cell.
    bool in[kColumnLanes];
    bool any = false;
    for (int l = 0; l < lanes; ++l) {
      const int64_t c = c0 + l;
      const int i = int(c % d.nx), j = int(c / d.nx);
      in[l] = (!e || (i >= e->x0 && i < e->x1 && j >= e->y0 && j < e->y1)) && flow.contains(i + pw.ox, j + pw.oy);
      any |= in[l];
      col[kFilmH * n + c] = -1.f;
      col[kFilmMoved * n + c] = 0.f;
    }
    if (!any) return;
    float base[kColumnLanes];
    int above[kColumnLanes];
    column_solid_tops(pw, c0, lanes, dry_threshold, 0.f, base, above);
    // The paint over the solid, summed up each column from its first layer over it (the same sums
    // in the same order as a column at a time: a layer below it adds an exact zero).
    float h[kColumnLanes], oil[kColumnLanes], r[kColumnLanes], y[kColumnLanes], b[kColumnLanes], dry[kColumnLanes];
    bool touched[kColumnLanes];
    const int layers = e ? e->layers : d.nz;
    int first = layers;
    for (int l = 0; l < lanes; ++l) {
      h[l] = oil[l] = r[l] = y[l] = b[l] = dry[l] = 0.f;
      touched[l] = false;
      first = above[l] < first ? above[l] : first;
    }
    for (int k = first; k < layers; ++k) {
      const int64_t id0 = int64_t(k) * n + c0;
      for (int l = 0; l < lanes; ++l) {
        const int64_t id = id0 + l;
        const bool over = k >= above[l];
        const float rho = over ? pw.density[id] : 0.f;
        touched[l] |= over && ((br.psi && br.psi[id] > 0.f) || (particle_density && particle_density[id] > 0.f));
        h[l] += rho, oil[l] += rho * pw.oil[id], dry[l] += rho * pw.dryness[id];
        r[l] += rho * pw.pigment_r[id], y[l] += rho * pw.pigment_y[id], b[l] += rho * pw.pigment_b[id];
      }
    }
    for (int l = 0; l < lanes; ++l) {
      if (!in[l]) continue;
      const int64_t c = c0 + l;
      // Means by division (a trace's h may be subnormal: its reciprocal overflows).
      const float hl = h[l];
      const auto mean = [hl](float q) { return hl > 0.f ? q / hl : 0.f; };
      // The bristles and the particles' paint are the grid's and the transfer's business; a bare
      // column is a film of nothing that paint may flow onto.
      col[kFilmH * n + c] = (hl <= film_max && !touched[l]) ? hl : -1.f;
      col[kFilmBase * n + c] = base[l];
      col[kFilmAbove * n + c] = float(above[l]);
      col[kFilmOil * n + c] = mean(oil[l]), col[kFilmDry * n + c] = mean(dry[l]);
      col[kFilmR * n + c] = mean(r[l]), col[kFilmY * n + c] = mean(y[l]), col[kFilmB * n + c] = mean(b[l]);
      film_rheology(col, n, c, f);
    }
  });
}

namespace detail {
/// Column c of the film after the signed inflows in[s] through its four faces (from[s] the column
/// across each): what stays, then each inflow with its column's paint (Algorithm 2 by mass; oil
/// and dryness by mass). Both columns of a face compute its transfer from the same values, bit for
/// bit, so what one gains the other loses. The base and the first layer over it are the same in
/// both sub-steps' planes (Grid::flow_film) and are not copied; a column that is no film, or a
/// bare one that nothing reached, passes on only its thickness and what crossed it (its paint's
/// fields are read only where it holds paint).
WB_HD WB_INLINE void film_column_after(const float* col, int64_t n, int64_t c, const float (&in)[4],
                                       const int64_t (&from)[4], const FilmFlow& f, float* next) {
  const float h = col[kFilmH * n + c];
  next[kFilmH * n + c] = h, next[kFilmMoved * n + c] = col[kFilmMoved * n + c];
  if (h < 0.f) return;
  float out = 0.f, gain = 0.f;
  for (int s = 0; s < 4; ++s) out += in[s] < 0.f ? -in[s] : 0.f, gain += in[s] > 0.f ? in[s] : 0.f;
  if (out == 0.f && gain == 0.f) {
    if (h > 0.f)
      for (const int p : {kFilmOil, kFilmR, kFilmY, kFilmB, kFilmDry, kFilmTau, kFilmK}) next[p * n + c] = col[p * n + c];
    return;
  }
  // What stays (none of a bare column's fields), then each inflow.
  float m = h - out;
  const bool kept = m > 0.f;
  Vec3 p = kept ? Vec3(col[kFilmR * n + c], col[kFilmY * n + c], col[kFilmB * n + c]) : Vec3(0.f, 0.f, 0.f);
  float oil = kept ? m * col[kFilmOil * n + c] : 0.f, dry = kept ? m * col[kFilmDry * n + c] : 0.f;
  for (int s = 0; s < 4; ++s) {
    if (!(in[s] > 0.f)) continue;
    const int64_t o = from[s];
    p = color_mix(p, Vec3(col[kFilmR * n + o], col[kFilmY * n + o], col[kFilmB * n + o]), maxf(m, 0.f), in[s]);
    oil += in[s] * col[kFilmOil * n + o], dry += in[s] * col[kFilmDry * n + o];
    m += in[s];
  }
  next[kFilmH * n + c] = m;
  next[kFilmR * n + c] = p.x, next[kFilmY * n + c] = p.y, next[kFilmB * n + c] = p.z;
  next[kFilmOil * n + c] = m > 0.f ? oil / m : 0.f, next[kFilmDry * n + c] = m > 0.f ? dry / m : 0.f;
  film_rheology(next, n, c, f);
  next[kFilmMoved * n + c] = col[kFilmMoved * n + c] + out + gain;
}
}  // namespace detail

void grid_film_update(GridDims d, const float* col, FilmFlow f, float* next, uint32_t* flowed) {
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_for(n, [=] WB_HD(int64_t c) {
    const int i = int(c % d.nx), j = int(c / d.nx);
    // Signed inflow through each face and the column it comes from; the window's own edges
    // carry nothing.
    const int64_t from[4] = {c - 1, c + 1, c - d.nx, c + d.nx};
    float in[4] = {0.f, 0.f, 0.f, 0.f};
    if (col[kFilmH * n + c] >= 0.f) {
      in[0] = i > 0 ? film_face(col, n, from[0], c, 0.f, f) : 0.f;
      in[1] = i + 1 < d.nx ? -film_face(col, n, c, from[1], 0.f, f) : 0.f;
      in[2] = j > 0 ? film_face(col, n, from[2], c, f.rho_g_sin, f) : 0.f;
      in[3] = j + 1 < d.ny ? -film_face(col, n, c, from[3], f.rho_g_sin, f) : 0.f;
      if (in[0] != 0.f || in[1] != 0.f || in[2] != 0.f || in[3] != 0.f) *flowed = 1u;  // all write 1
    }
    detail::film_column_after(col, n, c, in, from, f, next);
  });
}

/// After a pair of the film's sub-steps: another pair while paint crossed a face in this one and
/// pairs are left (a pair in which nothing moved leaves the film as it was, and so would every
/// later one); the flag is cleared for the next.
void grid_film_continue(uint32_t* flowed, uint32_t* pairs_done, int pairs, uint32_t* go) {
  parallel_for(1, [=] WB_HD(int64_t) {
    *pairs_done += 1u;
    *go = *flowed != 0u && *pairs_done < uint32_t(pairs) ? 1u : 0u;
    *flowed = 0u;
  });
}

namespace detail {
/// On the CPU backend the device's sums are the host's memory: an iteration launched past
/// convergence returns before its pass (on CUDA its threads return at once).
inline bool cpu_past_convergence(const CgGuard& guard) {
#if defined(__CUDACC__)
  (void)guard;
  return false;
#else
  return !guard.active();
#endif
}
}  // namespace detail

// --- surface tension of thin films (docs/GRID.md "Surface tension") --------------------------
// The film's faces are numbered f < n for the x face between columns c = f and c + 1, and
// n + c for the y face between c and c + nx. The capillary pressure under the surface s = base +
// h is sigma kappa, kappa = -lap(s) (small slopes); the flux across a face is q = -M dp/ds, M
// the Bingham film's mobility. Explicitly the step would need sub-steps of dx^4 / (16 sigma M):
// thousands a frame for oily paint. So the faces' fluxes F (cells of thickness over the step)
// are solved implicitly: F = -c G L0 (s + G^T F), c = dt sigma M / dx^4, G the faces' difference
// of two columns, L0 the film's graph Laplacian; that is
//   (1/c + G L0 G^T) F = -G L0 s,
// symmetric positive definite in the flowing faces' fluxes, by the viscous solve's Jacobi CG.

namespace detail {
/// A film column that holds paint. A paint's edge on the bare ground stays where it was laid (a
/// pinned contact line, as in drying coatings): surface tension acts on the paint's surface only,
/// across faces between two such columns.
WB_HD WB_INLINE bool film_wet(const float* col, int64_t n, int64_t c) { return col[kFilmH * n + c] > 0.f; }
WB_HD WB_INLINE float film_surface(const float* col, int64_t n, int64_t c) {
  return col[kFilmBase * n + c] + col[kFilmH * n + c];
}

/// The columns a and b of film face f; false where the face is the window's edge.
WB_HD WB_INLINE bool film_face_columns(const GridDims& d, int64_t n, int64_t f, int64_t& a, int64_t& b) {
  const bool y = f >= n;
  a = y ? f - n : f;
  if (y) {
    b = a + d.nx;
    return a / d.nx + 1 < d.ny;
  }
  b = a + 1;
  return a % d.nx + 1 < d.nx;
}

/// L0 v at wet film column c: the sum over its wet film neighbours of v(c) - v(neighbour) (none
/// across the paint's edge or out of the window: the surface's curvature stops there).
template <class V>
WB_HD WB_INLINE auto film_laplacian(const GridDims& d, const float* col, int64_t n, int64_t c, V v) {
  const int i = int(c % d.nx), j = int(c / d.nx);
  const auto vc = v(c);
  auto sum = vc - vc;
  if (i > 0 && film_wet(col, n, c - 1)) sum += vc - v(c - 1);
  if (i + 1 < d.nx && film_wet(col, n, c + 1)) sum += vc - v(c + 1);
  if (j > 0 && film_wet(col, n, c - d.nx)) sum += vc - v(c - d.nx);
  if (j + 1 < d.ny && film_wet(col, n, c + d.nx)) sum += vc - v(c + d.nx);
  return sum;
}

/// 1 / c of film face f between a and b, c = dt sigma M / dx^4, or 0 where the face does not flow:
/// the total driving gradient G (gravity's as film_face, and the capillary dp/ds from lap = L0 s)
/// against the upwind column's yield stress at the depth the groove sees (Bingham, Liu & Mei), M
/// the plug's mobility Y^2 (3h - Y) / (6 K), taken from the step's start.
WB_HD WB_INLINE double film_capillary_inverse(const float* col, int64_t n, const float* lap, int64_t a, int64_t b,
                                             float pull, const FilmFlow& f, float dt) {
  const float slope = film_surface(col, n, b) - film_surface(col, n, a);
  const float G = f.rho_g_cos * slope - pull + f.sigma * (lap[b] - lap[a]) / (f.cell * f.cell);
  const int64_t u = G > 0.f ? b : a;
  const float Gm = fabsf(G), h = minf(col[kFilmH * n + u], kFilmCapillaryDepth) * f.cell;
  const float tau_y = col[kFilmTau * n + u];
  if (!(Gm * h > tau_y)) return 0.0;
  const double Y = double(h) - double(tau_y) / double(Gm);
  const double M = Y * Y * (3.0 * double(h) - Y) / (6.0 * double(col[kFilmK * n + u]));
  const double cell2 = double(f.cell) * double(f.cell);
  const double c = double(dt) * double(f.sigma) * M / (cell2 * cell2);
  return c > 0.0 ? 1.0 / c : 0.0;
}

/// The flux of film face f in the CG's vector v (0 where the face does not flow).
WB_HD WB_INLINE double film_face_value(const uint32_t* flag, const uint32_t* idx, const double* v, int64_t f) {
  return flag[f] ? v[idx[f]] : 0.0;
}

/// (G^T v) at column c: what the flowing faces' fluxes v bring into it.
WB_HD WB_INLINE double film_inflow(const GridDims& d, int64_t n, const uint32_t* flag, const uint32_t* idx,
                                   const double* v, int64_t c) {
  const int i = int(c % d.nx), j = int(c / d.nx);
  double in = -film_face_value(flag, idx, v, c) - film_face_value(flag, idx, v, n + c);
  if (i > 0) in += film_face_value(flag, idx, v, c - 1);
  if (j > 0) in += film_face_value(flag, idx, v, n + c - d.nx);
  return in;
}
}  // namespace detail

/// lap = L0 s at the film's wet columns (cells), 0 elsewhere.
void grid_film_curvature(GridDims d, const float* col, float* lap) {
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_for(n, [=] WB_HD(int64_t c) {
    lap[c] = detail::film_wet(col, n, c)
                 ? detail::film_laplacian(d, col, n, c, [=](int64_t o) { return detail::film_surface(col, n, o); })
                 : 0.f;
  });
}

/// 1 at each film face that flows this step (film_capillary_inverse), 0 elsewhere.
void grid_film_capillary_flags(GridDims d, const float* col, const float* lap, FilmFlow f, float dt, uint32_t* flag) {
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_for(2 * n, [=] WB_HD(int64_t e) {
    int64_t a, b;
    flag[e] = detail::film_face_columns(d, n, e, a, b) && detail::film_wet(col, n, a) &&
                      detail::film_wet(col, n, b) &&
                      detail::film_capillary_inverse(col, n, lap, a, b, e >= n ? f.rho_g_sin : 0.f, f, dt) > 0.0
                  ? 1u
                  : 0u;
  });
}

/// The flowing faces' list (list[idx[f]] = f) and their count (the scan's last entry plus its flag).
void grid_film_capillary_list(int64_t faces, const uint32_t* flag, const uint32_t* idx, uint32_t* list,
                              int64_t* count) {
  parallel_for(faces, [=] WB_HD(int64_t e) {
    if (flag[e]) list[idx[e]] = uint32_t(e);
  });
  parallel_for(1, [=] WB_HD(int64_t) { *count = int64_t(idx[faces - 1]) + (flag[faces - 1] ? 1 : 0); });
}

/// Each flowing face's 1 / c, the Jacobi diagonal 1 / c + (G L0 G^T)_ff, the right-hand side
/// b = -G L0 s in r, the first guess x = 0 and A x = 0 in q.
void grid_film_capillary_setup(GridDims d, const float* col, const float* lap, const uint32_t* list, ListCount cnt,
                               FilmFlow f, float dt, double* cinv, double* diag, double* r, double* x, double* q) {
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_for_count(cnt.n, cnt.capacity, [=] WB_HD(int64_t e) {
    const int64_t face = list[e];
    int64_t a, b;
    detail::film_face_columns(d, n, face, a, b);
    // (G^T e_f)^T L0 (G^T e_f) = deg a + deg b + 2: a and b are film neighbours. A column's
    // degree (its wet neighbours) is L0 of its own indicator there.
    const auto degree = [=](int64_t c) {
      return detail::film_laplacian(d, col, n, c, [=](int64_t o) { return o == c ? 1.f : 0.f; });
    };
    cinv[e] = detail::film_capillary_inverse(col, n, lap, a, b, face >= n ? f.rho_g_sin : 0.f, f, dt);
    diag[e] = cinv[e] + double(degree(a)) + double(degree(b)) + 2.0;
    r[e] = double(lap[a]) - double(lap[b]);
    x[e] = 0.0, q[e] = 0.0;
  });
}

/// q = A p = p / c + G L0 G^T p over the flowing faces, and p.q.
void grid_film_capillary_apply(GridDims d, const float* col, const uint32_t* list, ListCount cnt,
                               const uint32_t* flag, const uint32_t* idx, const double* cinv, const double* p,
                               double* q, double* pq, CgGuard guard, SumScratch s) {
  if (detail::cpu_past_convergence(guard)) return;  // p.Ap is not read past convergence
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_sum_count(
      cnt.n, cnt.capacity,
      [=] WB_HD(int64_t e) {
        if (!guard.active()) return 0.0;
        const int64_t face = list[e];
        int64_t a, b;
        detail::film_face_columns(d, n, face, a, b);
        const auto inflow = [=](int64_t c) { return detail::film_inflow(d, n, flag, idx, p, c); };
        const double w_a = detail::film_laplacian(d, col, n, a, inflow);
        const double w_b = detail::film_laplacian(d, col, n, b, inflow);
        q[e] = cinv[e] * p[e] + (w_b - w_a);
        return p[e] * q[e];
      },
      pq, s);
}

/// The film after the solved fluxes x: each face carries its flux from the upwind column, at most
/// a quarter of that column's film (it has four faces), as the gravity's sub-steps do.
void grid_film_capillary_move(GridDims d, const float* col, const uint32_t* flag, const uint32_t* idx,
                              const double* x, FilmFlow f, float* next) {
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_for(n, [=] WB_HD(int64_t c) {
    const int i = int(c % d.nx), j = int(c / d.nx);
    const int64_t from[4] = {c - 1, c + 1, c - d.nx, c + d.nx};
    // The face's flux, a -> b where positive, bounded by the upwind film.
    const auto carried = [=](int64_t face, int64_t a, int64_t b) {
      if (!flag[face]) return 0.f;  // a face that does not flow, or one beside no film
      const double F = x[idx[face]];
      const float t = float(F > 0.0 ? F : -F), m = minf(t, 0.25f * col[kFilmH * n + (F > 0.0 ? a : b)]);
      return F > 0.0 ? m : -m;
    };
    float in[4] = {0.f, 0.f, 0.f, 0.f};
    if (detail::film_wet(col, n, c)) {
      in[0] = i > 0 ? carried(c - 1, c - 1, c) : 0.f;
      in[1] = i + 1 < d.nx ? -carried(c, c, c + 1) : 0.f;
      in[2] = j > 0 ? carried(n + c - d.nx, c - d.nx, c) : 0.f;
      in[3] = j + 1 < d.ny ? -carried(n + c, c, c + d.nx) : 0.f;
    }
    detail::film_column_after(col, n, c, in, from, f, next);
  });
}

void grid_film_write(GridDims d, PaintWindowView pw, const float* col) {
  const int64_t n = int64_t(d.nx) * d.ny;
  parallel_for(n, [=] WB_HD(int64_t c) {
    if (!(col[kFilmMoved * n + c] > 0.f)) return;
    // The film is laid again from the first layer over what it lies on, full cells first.
    float left = col[kFilmH * n + c];
    const Vec3 p(col[kFilmR * n + c], col[kFilmY * n + c], col[kFilmB * n + c]);
    const float oil = col[kFilmOil * n + c], dry = col[kFilmDry * n + c];
    for (int k = int(col[kFilmAbove * n + c]); k < d.nz; ++k) {
      const int64_t id = int64_t(k) * n + c;
      const float rho = minf(left, 1.f);
      left -= rho;
      const bool paint = rho > 0.f;
      pw.density[id] = rho;
      pw.pigment_r[id] = paint ? p.x : 0.f, pw.pigment_y[id] = paint ? p.y : 0.f, pw.pigment_b[id] = paint ? p.z : 0.f;
      pw.oil[id] = paint ? oil : 0.f, pw.dryness[id] = paint ? dry : 0.f;
    }
  });
}

void grid_effective_viscosity(GridView g, JointOil oil, HerschelBulkley stiff, HerschelBulkley oily, float m,
                              float* mu) {
  const GridDims d = g.d;
  for_cells(d, g.extent, [=] WB_HD(int64_t c, int i, int j, int k) {
    if (g.cls[c] != kCellLiquid) {
      mu[c] = 0.f;
      return;
    }
    mu[c] = apparent_viscosity(rheology_at_oil(oil.at(c), stiff, oily), cell_strain_rate(g, i, j, k), m);
  });
}

void grid_viscous_flags(GridView g, uint32_t* flag) {
  // The extent's faces: beyond them every flag is 0 already, as the fluid flags are (the faces
  // a step's liquid held are visited once more by the next step, GridExtent::dirty_box).
  const GridDims d = g.d;
  for_faces(d, g.extent,
            [=] WB_HD(int c, int64_t f, int, int, int) { flag[global_face(d, c, f)] = g.fluid[c][f] ? 1u : 0u; });
}

void grid_viscous_list(GridView g, const uint32_t* idx, uint32_t* list) {
  const GridDims d = g.d;
  // Fluid faces lie below the extent's layers; the list and idx are of every face.
  for_faces(d, g.extent, [=] WB_HD(int c, int64_t f, int, int, int) {
    if (!g.fluid[c][f]) return;
    const int64_t t = global_face(d, c, f);
    list[idx[t]] = uint32_t(t);
  });
}

namespace detail {
/// Component, index and position of the face of list entry e.
WB_HD WB_INLINE int64_t list_face(const GridDims& d, const uint32_t* list, int64_t e, int& c, int& i, int& j,
                                  int& k) {
  int64_t f;
  split_face_below(d, d.nz, int64_t(list[e]), c, f);
  d.decompose_face(c, f, i, j, k);
  return f;
}
}  // namespace detail

void grid_viscous_count(GridView g, const uint32_t* idx, int64_t* run, double* total) {
  // idx is the exclusive scan of the fluid flags of every face: the last entry plus the last
  // face's own flag is the count.
  const GridDims d = g.d;
  parallel_for(1, [=] WB_HD(int64_t) {
    const int64_t last = detail::all_faces(d) - 1;
    int c;
    int64_t f;
    detail::split_face_below(d, d.nz, last, c, f);
    const int64_t n = int64_t(idx[last]) + (g.fluid[c][f] ? 1 : 0);
    *run = n;
    *total = double(n);
  });
}

void grid_viscous_setup(GridView g, const uint32_t* list, ListCount n, const uint32_t* idx, const float* mu,
                        float nu_scale, float* nu, int32_t* nb, double* diag, double* b, double* x, FaceFields guess) {
  const GridDims d = g.d;
  parallel_for_count(n.n, n.capacity, [=] WB_HD(int64_t e) {
    int c, i, j, k;
    detail::list_face(d, list, e, c, i, j, k);
    nu[e] = face_nu_dt(g, mu, c, i, j, k, nu_scale);
  });
  parallel_for_count(n.n, n.capacity, [=] WB_HD(int64_t e) {
    int c, i, j, k;
    const int64_t f = detail::list_face(d, list, e, c, i, j, k);
    viscous_row(g, nu, idx, e, c, i, j, k, g.vel[c][f], nb + 6 * e, diag[e], b[e]);
    x[e] = guess.c[c][f];  // the first guess: the advected velocity before the forces (Grid::apply_viscosity)
  });
}


void grid_viscous_apply(ListCount n, const float* nu, const int32_t* nb, const double* diag, const double* p,
                        double* q, double* pq, CgGuard guard, SumScratch s) {
  if (detail::cpu_past_convergence(guard)) return;  // p.Ap is not read past convergence
  parallel_sum_count(
      n.n, n.capacity,
      [=] WB_HD(int64_t e) {
        if (!guard.active()) return 0.0;
        q[e] = viscous_apply(nu, nb, p, diag[e], e);
        return p[e] * q[e];
      },
      pq, s);
}

void grid_pcg_start(ListCount n, double* r, const double* ax, const double* diag, double* p, double* rz, double* bz,
                    SumScratch s) {
  // r holds b (grid_viscous_setup): b.D^-1 b first, then r = b - A x, z = D^-1 r (not kept: the
  // passes that need it divide again) and p = z.
  parallel_sum_count(n.n, n.capacity, [=] WB_HD(int64_t e) { return r[e] * r[e] / diag[e]; }, bz, s);
  parallel_sum_count(
      n.n, n.capacity,
      [=] WB_HD(int64_t e) {
        r[e] -= ax[e];
        p[e] = r[e] / diag[e];
        return r[e] * p[e];
      },
      rz, s);
}

void grid_pcg_update(ListCount n, CgGuard guard, const double* pq, const double* p, const double* q,
                     const double* diag, double* x, double* r, double* rz, double* iterations, SumScratch s) {
  if (detail::cpu_past_convergence(guard)) {
    *rz = *guard.rz;  // as the pass would sum it (to rounding)
    return;
  }
  parallel_sum_count(
      n.n, n.capacity,
      [=] WB_HD(int64_t e) {
        // Past convergence nothing moves, and the sum is the last r.z again (to rounding).
        if (!guard.active()) return r[e] * r[e] / diag[e];
        if (e == 0) *iterations += 1.0;
        // alpha = (r.z) / (p.Ap) from the device sums; 0 (no step) where p.Ap is not positive,
        // which an SPD system reaches only by round-off at convergence.
        const double alpha = *pq > 0.0 ? *guard.rz / *pq : 0.0;
        x[e] += alpha * p[e];
        r[e] -= alpha * q[e];
        return r[e] * r[e] / diag[e];  // r.z with z = D^-1 r
      },
      rz, s);
}

void grid_pcg_direction(ListCount n, CgGuard guard, const double* rz_new, const double* r, const double* diag,
                        double* p) {
  if (detail::cpu_past_convergence(guard)) return;
  parallel_for_count(n.n, n.capacity, [=] WB_HD(int64_t e) {
    if (!guard.active()) return;
    const double beta = *rz_new / *guard.rz;
    p[e] = r[e] / diag[e] + beta * p[e];
  });
}

void grid_pcg_continue(double* rz, const double* rz_new, const double* bnorm, double tol2, const double* iterations,
                       int max_it, uint32_t* go) {
  // The iteration's r.z becomes the current one; another iteration while the test fails and the
  // limit is not reached.
  parallel_for(1, [=] WB_HD(int64_t) {
    *rz = *rz_new;
    *go = CgGuard{rz, bnorm, tol2}.active() && *iterations < double(max_it) ? 1u : 0u;
  });
}

void grid_viscous_write(GridView g, const uint32_t* list, ListCount n, const double* x) {
  const GridDims d = g.d;
  parallel_for_count(n.n, n.capacity, [=] WB_HD(int64_t e) {
    int c;
    int64_t f;
    detail::split_face_below(d, d.nz, int64_t(list[e]), c, f);
    g.vel[c][f] = float(x[e]);
  });
}

void grid_rhs(GridView g, const float* rho, float inv_dt, float* b) {
  const GridDims d = g.d;
  for_cells(d, g.extent, [=] WB_HD(int64_t c, int i, int j, int k) {
    if (g.cls[c] != kCellLiquid) {
      b[c] = 0.f;
      return;
    }
    b[c] = compression_source(rho ? rho[c] : 0.f, inv_dt) - cell_divergence(g, i, j, k);
  });
}

void poisson_jacobi(PoissonView s, const float* b, const float* x, float* out, float omega) {
  for_cells(s.d, s.extent,
            [=] WB_HD(int64_t c, int i, int j, int k) { out[c] = jacobi_update(s, b, x, c, i, j, k, omega); });
}

void poisson_residual(PoissonView s, const float* b, const float* x, float* r) {
  for_cells(s.d, s.extent, [=] WB_HD(int64_t c, int i, int j, int k) {
    r[c] = s.cls[c] == kCellLiquid ? b[c] - poisson_apply(s, x, c, i, j, k) : 0.f;
  });
}

void poisson_chebyshev(PoissonView s, const float* b, const float* x, const float* x_prev, float* out, float omega_k) {
  for_cells(s.d, s.extent, [=] WB_HD(int64_t c, int i, int j, int k) {
    const float xj = jacobi_update(s, b, x, c, i, j, k, 1.f);
    out[c] = s.cls[c] == kCellLiquid ? omega_k * (xj - x_prev[c]) + x_prev[c] : 0.f;
  });
}

void poisson_fixed_point_first(PoissonView s, const float* r, const float* y, float* out, float alpha) {
  // One Jacobi sweep on the residual r started from alpha * y (Eq. 3, inner term).
  for_cells(s.d, s.extent, [=] WB_HD(int64_t c, int i, int j, int k) {
    if (s.cls[c] != kCellLiquid) {
      out[c] = 0.f;
      return;
    }
    float diag, off;
    poisson_row(s, y, i, j, k, diag, off);
    out[c] = diag > 1e-6f ? (r[c] + alpha * off) / diag : 0.f;
  });
}

void poisson_fixed_point_second(PoissonView s, const float* r, const float* z, float* y_out, float* x) {
  // Second Jacobi sweep, then x += y (the pressure applied is the sum of the corrections).
  for_cells(s.d, s.extent, [=] WB_HD(int64_t c, int i, int j, int k) {
    const float y = jacobi_update(s, r, z, c, i, j, k, 1.f);
    y_out[c] = y;
    x[c] += y;
  });
}

void poisson_apply_all(PoissonView s, const float* x, float* out) {
  for_cells(s.d, s.extent,
            [=] WB_HD(int64_t c, int i, int j, int k) { out[c] = poisson_apply(s, x, c, i, j, k); });
}

void grid_apply_pressure(GridView g, const float* p) {
  const GridDims d = g.d;
  for_faces(d, g.extent, [=] WB_HD(int c, int64_t f, int i, int j, int k) {
    g.vel[c][f] = projected_face_velocity(g, p, c, i, j, k);
  });
}

void grid_extrapolate(GridView g) {
  const GridDims d = g.d;
  // Writes only faces that touch no liquid, reads only faces that do: safe in place.
  for_faces(d, g.extent, [=] WB_HD(int c, int64_t f, int i, int j, int k) {
    if (g.theta[c][f] <= 0.f) {
      g.vel[c][f] = g.solid_vel[c][f];
      return;
    }
    if (g.fluid[c][f]) return;
    g.vel[c][f] = extrapolated_face_velocity(g, c, i, j, k);
  });
}

void grid_extent(GridDims d, const float* before, const float* after, GridExtent* e) {
  parallel_for(1, [=] WB_HD(int64_t) {
    // The liquid's cells before the advection and now, and a cell around them: the faces
    // extrapolation writes. before and after: the joint top, then the box's maxima.
    const float top = maxf(maxf(before[0], after[0]), 0.f);
    const int now = top + 1.f < float(d.nz) ? int(top) + 1 : d.nz;
    int a[4], b[4], box[4], visit[4];
    column_box(d, before + 1, 1, a);
    column_box(d, after + 1, 1, b);
    box_union(a, b, box);
    // With what the last step visited for its liquid, which goes back to its value now.
    box_union(box, e->dirty_box, visit);
    set_extent(*e, d, now > e->dirty ? now : e->dirty, visit[0], visit[1], visit[2], visit[3]);
    e->dirty = now;
    for (int s = 0; s < 4; ++s) e->dirty_box[s] = box[s];
  });
}

void grid_dry(PaintWindowView pw, float amount) {
  parallel_for(pw.size(), [=] WB_HD(int64_t c) {
    if (pw.density[c] > 0.f) pw.dryness[c] = minf(pw.dryness[c] + amount, 1.f);
  });
}

void grid_shift_edges(float* dst, int ex, int ey, int ez, int dx, int dy) {
  // A lattice shifted by (dx, dy) as one offset copy (ActiveWindow::shift_faces) takes, at the
  // x and y edges, elements of the neighbouring row or layer: they have no source and are zeroed
  // here. Per layer: the |dy| rows whose source row is outside, then |dx| elements of each other row.
  const int ax = dx < 0 ? -dx : dx, ay = dy < 0 ? -dy : dy;
  const int64_t rows = int64_t(ay) * ex, layer = rows + int64_t(ey - ay) * ax;
  parallel_for(int64_t(ez) * layer, [=] WB_HD(int64_t t) {
    const int64_t k = t / layer, r = t - k * layer;
    int i, j;
    if (r < rows) {
      j = (dy > 0 ? ey - dy : 0) + int(r / ex);
      i = int(r % ex);
    } else {
      const int64_t q = r - rows;
      j = (dy < 0 ? -dy : 0) + int(q / ax);
      i = (dx > 0 ? ex - dx : 0) + int(q % ax);
    }
    dst[(k * ey + j) * ex + i] = 0.f;
  });
}

void grid_max_abs_fluid_velocity(GridView g, float* out) {
  const GridDims d = g.d;
  parallel_for(detail::all_faces(d), [=] WB_HD(int64_t t) {
    int c;
    int64_t f;
    detail::split_face_below(d, d.nz, t, c, f);
    out[t] = g.fluid[c][f] ? fabsf(g.vel[c][f]) : 0.f;
  });
}

void grid_square(const float* x, float* out, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t c) { out[c] = x[c] * x[c]; });
}

void grid_scale(float* x, float s, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t c) { x[c] *= s; });
}

void grid_fill_hash(float* x, const uint8_t* cls, int64_t n, uint32_t seed) {
  parallel_for(n, [=] WB_HD(int64_t c) {
    uint32_t h = uint32_t(c) * 747796405u + seed * 2891336453u + 1u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    h = (h >> 22u) ^ h;
    x[c] = cls[c] == kCellLiquid ? float(h & 0xFFFFFFu) / float(0x1000000) - 0.5f : 0.f;
  });
}

}  // namespace wb::WB_BACKEND_NS
