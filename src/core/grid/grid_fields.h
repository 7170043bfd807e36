// Grid stage state (paper §4.2): the staggered (MAC) velocity on cell faces, cell
// classes, open face fractions and the solid (bristle) face velocity, as POD views.
// Units: positions in window cells (cell (i,j,k) spans [i,i+1) x [j,j+1) x [k,k+1)),
// velocity in cells/s. The paint scalars live in PaintWindow (core/canvas/window.h).
#pragma once
#include <math.h>  // ::isfinite for core/math/vec.h under g++

#include <cstdint>

#include "core/canvas/window.h"
#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

/// Cell classes of the projection.
enum CellClass : uint8_t {
  kCellAir = 0,     ///< p = 0 (free surface)
  kCellLiquid = 1,  ///< unknown of the pressure system
  kCellSolid = 2,   ///< dried paint, or off the canvas: never moved, closed faces
};

/// The columns where paint flows, canvas cells [x0, x1) x [y0, y1): the window's less a band along
/// its walls, so that the region follows the brush cell by cell while the window moves in snaps
/// (Grid::set_flow_columns; docs/GRID.md "The window's walls"). Cells outside are walls, as cells
/// off the canvas are. The default holds every column.
struct FlowColumns {
  int x0 = -(1 << 30), x1 = 1 << 30, y0 = -(1 << 30), y1 = 1 << 30;
  WB_HD bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
};

/// Rasterised bristles from the brush, cell-centred on the window grid (device pointers;
/// psi == nullptr means no brush). psi is the bristle volume fraction (min(psi,1) is the
/// solid fraction); vx, vy, vz the psi-weighted mean bristle velocity, cells/s.
struct BristleField {
  const float* psi = nullptr;
  const float* vx = nullptr;
  const float* vy = nullptr;
  const float* vz = nullptr;
};

/// Index helpers of the MAC layout. u: (nx+1) x ny x nz, v: nx x (ny+1) x nz, w: nx x ny x (nz+1).
struct GridDims {
  int nx, ny, nz;
  WB_HD int64_t cells() const { return int64_t(nx) * ny * nz; }
  WB_HD int64_t nu() const { return int64_t(nx + 1) * ny * nz; }
  WB_HD int64_t nv() const { return int64_t(nx) * (ny + 1) * nz; }
  WB_HD int64_t nw() const { return int64_t(nx) * ny * (nz + 1); }
  WB_HD int64_t cell(int i, int j, int k) const { return (int64_t(k) * ny + j) * nx + i; }
  WB_HD int64_t uidx(int i, int j, int k) const { return (int64_t(k) * ny + j) * (nx + 1) + i; }
  WB_HD int64_t vidx(int i, int j, int k) const { return (int64_t(k) * (ny + 1) + j) * nx + i; }
  WB_HD int64_t widx(int i, int j, int k) const { return (int64_t(k) * ny + j) * nx + i; }
  /// Face count and index of component c (0 = u, 1 = v, 2 = w).
  WB_HD int64_t faces(int c) const { return c == 0 ? nu() : (c == 1 ? nv() : nw()); }
  WB_HD int64_t fidx(int c, int i, int j, int k) const {
    return c == 0 ? uidx(i, j, k) : (c == 1 ? vidx(i, j, k) : widx(i, j, k));
  }
  /// Face extent along each axis for component c.
  WB_HD void face_extent(int c, int& ex, int& ey, int& ez) const {
    ex = nx + (c == 0);
    ey = ny + (c == 1);
    ez = nz + (c == 2);
  }
  /// A window's cell and face indices fit in 32 bits (PaintWindow requires it), and two 32-bit
  /// divisions cost a fraction of three 64-bit ones (a GPU emulates those in software).
  WB_HD void decompose_face(int c, int64_t f, int& i, int& j, int& k) const {
    int ex, ey, ez;
    face_extent(c, ex, ey, ez);
    split(uint32_t(f), uint32_t(ex), uint32_t(ey), i, j, k);
  }
  WB_HD void decompose_cell(int64_t c, int& i, int& j, int& k) const {
    split(uint32_t(c), uint32_t(nx), uint32_t(ny), i, j, k);
  }
  WB_HD static void split(uint32_t t, uint32_t ex, uint32_t ey, int& i, int& j, int& k) {
    const uint32_t row = t / ex, layer = row / ey;
    i = int(t - row * ex);
    j = int(row - layer * ey);
    k = int(layer);
  }
};

/// The part of the window a stage visits (device memory; docs/GRID.md "Work in proportion to the
/// paint"): after the joint fields (grid_extent) and the advection's (grid_first_extent, then
/// the one the host sets from the advection's read). The columns [x0, x1) x [y0, y1) below `layers` hold every cell with
/// paint, particles or liquid and a margin around them; outside it no face is fluid. Stages
/// over this extent leave the rest as it was, and what the last step visited for its liquid
/// (`dirty`, `dirty_box`) is visited once more, so that what it held goes back to its value for
/// cells without liquid.
struct GridExtent {
  int64_t cells;    ///< the box's cells: (x1 - x0) (y1 - y0) layers
  int64_t faces;    ///< the faces of those cells: u and v below `layers`, w up to layer `layers`
  int32_t layers;   ///< cells with k < layers
  int32_t dirty;    ///< the layers holding liquid at the last step
  int64_t classes;  ///< the cells classify writes: one layer more, whose class the top faces read
  int32_t x0, x1, y0, y1;  ///< the columns visited
  int32_t dirty_box[4];    ///< the columns holding liquid at the last step (x0, x1, y0, y1)
};

/// The Herschel–Bulkley parameters of one paint: tau = tau_y + K gamma_dot^n above the yield stress.
struct HerschelBulkley {
  float tau_y;  ///< yield stress, Pa
  float K;      ///< consistency, Pa s^n
  float n;      ///< flow index (< 1: shear-thinning)
};

/// What a thin film's flow needs (Grid::flow_film): the paint's end members, gravity across the
/// canvas and down it (Pa per m of slope, Pa/m), the cell (m), the sub-step (s) and the paint's
/// surface tension (N/m).
struct FilmFlow {
  HerschelBulkley stiff, oily;  ///< the paint's end members (Grid::paint_end_members)
  float rho_g_cos;  ///< rho0 g cos(tilt): the pressure gradient per unit slope of the surface, Pa/m
  float rho_g_sin;  ///< rho0 g sin(tilt): the pull down the canvas (+y), Pa/m
  float cell;       ///< m
  float dt;         ///< s
  float sigma;      ///< N/m
};

/// The depth (cells) of a film that a groove the grid holds sees: a capillary wave of wavenumber k
/// on a film deeper than 1/k shears only the top 1/k or so (creeping flow over a floor: the
/// levelling rate tends to sigma k / (2 mu) for kh >> 1, where lubrication's sigma k^4 h^3 / (3 mu)
/// keeps growing), and the lubrication film matches that rate and the stress at its base with
/// the depth 1.14 / k. The bristles' streaks are 2-3 cells apart (k = 2 pi / 2.5 cells): 0.45 cells.
inline constexpr float kFilmCapillaryDepth = 0.45f;

/// Per film column in Grid::flow_film's scratch: the film's thickness (cells; negative where the
/// column is no film), the top of what it lies on (cells), the first layer above that, its
/// mass-weighted oil, pigment and dryness, and the paint that crossed its faces over the step
/// (cells; 0: its cells stay as they are): kFilmFields planes of nx * ny.
/// kFilmTau and kFilmK are the Herschel-Bulkley tau_y and K at the column's oil (rheology_at_oil),
/// kept with the oil so that a face's flux does not form them again in every sub-step.
enum FilmField : int {
  kFilmH,
  kFilmBase,
  kFilmAbove,
  kFilmOil,
  kFilmR,
  kFilmY,
  kFilmB,
  kFilmDry,
  kFilmMoved,
  kFilmTau,
  kFilmK,
  kFilmFields
};

/// Thickness (cells) a film face carries in a sub-step from column a to b (negative: b to a).
/// A gravity-driven Bingham film (Liu & Mei, J. Fluid Mech. 207, 505, 1989): with the driving
/// gradient G (Pa/m) the base's shear stress is G h; below the yield stress nothing flows; above it
/// the paint shears below the plug's height Y = h - tau_y / G and the flux is G Y^2 (3h - Y) / (6 K),
/// the upwind column's h, tau_y and K (n taken as 1: the oily paint that flows is nearly Newtonian).
/// At most a quarter of the upwind film leaves through one face a sub-step (it has four).
WB_HD WB_INLINE float film_face(const float* col, int64_t n, int64_t a, int64_t b, float pull, const FilmFlow& f) {
  const float ha = col[kFilmH * n + a], hb = col[kFilmH * n + b];
  if (ha < 0.f || hb < 0.f) return 0.f;
  const float slope = (col[kFilmBase * n + b] + hb) - (col[kFilmBase * n + a] + ha);  // cells per cell
  const float G = f.rho_g_cos * slope - pull;  // dp/ds along a -> b, Pa/m: the paint flows down it
  const int64_t u = G > 0.f ? b : a;
  const float hu = col[kFilmH * n + u];
  // An upwind column with no paint carries none, and its paint's fields are not read: a bare
  // column that nothing reached in a sub-step passes on only its thickness (film_column_after),
  // so the other plane's fields there are whatever an earlier step or allocation left.
  if (!(hu > 0.f)) return 0.f;
  const float Gm = fabsf(G), h = hu * f.cell, tau_y = col[kFilmTau * n + u];
  if (!(Gm * h > tau_y)) return 0.f;
  const float Y = h - tau_y / Gm;
  const float q = Gm * Y * Y * (3.f * h - Y) / (6.f * col[kFilmK * n + u]);  // m^2/s
  const float t = minf(q * f.dt / (f.cell * f.cell), 0.25f * hu);
  return G > 0.f ? -t : t;
}

/// The oil fraction of the joint paint (§4.3: grid and particles) in a cell, mass-weighted: the
/// paint near the bristles is mostly particles, and a cell liquid by its particles alone has the
/// rheology of their paint, not of the grid's empty cell (oil 0, the stiffest).
/// particle_oil: the particles' volume times oil fraction, rasterised; null: the grid's oil.
struct JointOil {
  const float* density = nullptr;
  const float* oil = nullptr;
  const float* particle_density = nullptr;
  const float* particle_oil = nullptr;
  WB_HD float at(int64_t c) const {
    if (!particle_oil) return oil[c];
    const float total = density[c] + particle_density[c];
    return total > 0.f ? (density[c] * oil[c] + particle_oil[c]) / total : oil[c];
  }
};

/// The viscous solve's list length as the device counted it (the host does not wait for it):
/// its kernels run over the first *n of `capacity` entries (parallel_for_count); *n is 0 when
/// the list outgrew the capacity, and the solve's one read tells the host to size it again.
struct ListCount {
  const int64_t* n = nullptr;
  int64_t capacity = 0;
};

/// A MAC field's three components, read only (the viscous solve's first guess).
struct FaceFields {
  const float* c[3] = {nullptr, nullptr, nullptr};
};

/// The viscous CG's test of convergence, made on the device by every kernel of an iteration:
/// the iteration runs while r.z > tol2 b.D^-1 b (and r.z > 0), so that iterations launched past
/// convergence do nothing and the host need not read r.z to stop them. rz null: always run.
struct CgGuard {
  const double* rz = nullptr;
  const double* bnorm = nullptr;
  double tol2 = 0.0;
  WB_HD bool active() const { return !rz || (*rz > tol2 * *bnorm && *rz > 0.0); }
};

/// Columns of the window in tiles of kPaintTile x kPaintTile: the paint's advection visits the
/// tiles within its reach of the paint (docs/GRID.md "Work in proportion to the paint").
constexpr int kPaintTile = 8;
/// The paint advection's plan for a step, made on the device from the step's maxima
/// (grid_advect_plan) so that the host launches the passes without reading them: how far the
/// paint moves along each axis and the layers and tiles its passes visit. It comes back to the
/// host with the step's record (Grid::take_record).
struct AdvectPlan {
  /// Cells a pass along each axis walks: the paint's largest outflow over the step, rounded up,
  /// and 1; 0: no flow along the axis, and its pass writes nothing.
  int32_t reach[3];
  int32_t top;       ///< the layers holding paint
  int32_t layers;    ///< the layers the passes advect: top and the reach up
  int32_t deep;      ///< the layers the passes read: layers, the reach up and a cell more
  int32_t reach_tiles;  ///< tiles the passes reach across (x or y)
  int32_t halo_tiles;   ///< the ring of tiles beyond them the passes read
  int32_t passes;       ///< the axes along which paint flows (reach > 0)
  float courant;        ///< the largest one-axis outflow of a painted cell over the step, cells
};

/// The grid's figures that the device makes in a step and the host learns with the step's
/// record (Grid::record_into, Grid::take_record): the advection's plan and the viscous solve's
/// sums (r.z, r.z next, p.Ap, b.D^-1 b, the iterations, the fluid faces).
struct GridRecord {
  AdvectPlan advect;
  double viscosity[6];
};

/// Whether the passes of a step before its pass n (the axes in `order`: 0 x y z, 1 z y x) left
/// the paint in the scratch buffers: each pass along an axis with flow writes the buffers the
/// last one read from; one along an axis without flow writes nothing.
WB_HD WB_INLINE bool advect_in_scratch(const AdvectPlan& p, int order, int n) {
  int made = 0;
  for (int m = 0; m < n; ++m) made += p.reach[order == 0 ? m : 2 - m] > 0 ? 1 : 0;
  return made % 2 == 1;
}

/// What grid_copy_paint_tiles copies: the paint into the scratch buffers, every cell the
/// advection's passes read (the listed and halo tiles, the plan's `deep` layers); or the passes'
/// result back, the cells they write (the listed tiles, `layers`), and only where an odd number of
/// passes that moved paint left it in the scratch (advect_in_scratch).
enum class TileCopy : int { kIntoScratch, kResultBack };

/// The tiles the advection visits (device lists and counts, grid.cpp). counts: the active tiles,
/// the halo tiles around them, then the cells of the active tiles below the plan's `layers`, of
/// the active tiles below its `deep` and of the halo tiles below `deep`, in rows of kPaintTile
/// cells.
struct PaintTiles {
  const int32_t* active;
  const int32_t* halo;
  const int64_t* counts;
  const AdvectPlan* plan;  ///< the step's reach and layers (device)
  int tiles_x;
  int64_t capacity;  ///< every tile's rows, the window's depth deep (tiles overhang its edges)
};

/// Faces of the cells below `layers`, as one list u | v | w: each a prefix of its component's
/// array (z is the slowest index). With layers = nz, every face.
WB_HD WB_INLINE int64_t faces_below(int nx, int ny, int nz, int layers) {
  const int w_layers = layers < nz ? layers + 1 : nz + 1;
  return int64_t(nx + 1) * ny * layers + int64_t(nx) * (ny + 1) * layers + int64_t(nx) * ny * w_layers;
}

/// Density below which paint in a cell is a trace, cells: it neither sets the advection's passes
/// nor its bounds.
constexpr float kTraceDensity = 1e-6f;

/// An extent of the columns [x0, x1) x [y0, y1) below `layers` (dirty unchanged).
WB_HD WB_INLINE void set_extent(GridExtent& e, const GridDims& d, int layers, int x0, int x1, int y0, int y1) {
  e.layers = layers;
  e.x0 = x0, e.x1 = x1, e.y0 = y0, e.y1 = y1;
  const int64_t bx = x1 - x0, by = y1 - y0;
  e.cells = bx * by * layers;
  e.faces = faces_below(int(bx), int(by), d.nz, layers);
  e.classes = bx * by * (layers < d.nz ? layers + 1 : d.nz);
}
/// The columns [x0, x1) x [y0, y1) of the box whose maxima of x, -x, y, -y are m[0..3], grown
/// by `margin` and clamped to the window; empty (all 0) where no column counted.
WB_HD WB_INLINE void column_box(const GridDims& d, const float* m, int margin, int box[4]) {
  if (!(m[0] >= -m[1] && m[2] >= -m[3])) {
    box[0] = box[1] = box[2] = box[3] = 0;
    return;
  }
  const int x0 = int(-m[1]) - margin, x1 = int(m[0]) + 1 + margin;
  const int y0 = int(-m[3]) - margin, y1 = int(m[2]) + 1 + margin;
  box[0] = x0 > 0 ? x0 : 0;
  box[1] = x1 < d.nx ? x1 : d.nx;
  box[2] = y0 > 0 ? y0 : 0;
  box[3] = y1 < d.ny ? y1 : d.ny;
}

/// The smallest box (x0, x1, y0, y1) holding boxes a and b; an empty box adds nothing.
WB_HD WB_INLINE void box_union(const int a[4], const int b[4], int out[4]) {
  const bool a_empty = a[0] >= a[1] || a[2] >= a[3], b_empty = b[0] >= b[1] || b[2] >= b[3];
  for (int s = 0; s < 4; ++s)
    out[s] = a_empty ? b[s] : (b_empty ? a[s] : (s % 2 == 0 ? imin(a[s], b[s]) : imax(a[s], b[s])));
}

/// An extent of `layers` layers, every column (dirty unchanged).
WB_HD WB_INLINE void set_layers(GridExtent& e, const GridDims& d, int layers) {
  set_extent(e, d, layers, 0, d.nx, 0, d.ny);
}
/// The cell of index t among an extent's cells (x fastest, then y, then z). A window's cells
/// and faces number fewer than 2^32 (GridDims::split): 32-bit divisions, the cheaper.
WB_HD WB_INLINE int64_t extent_cell(const GridDims& d, const GridExtent& e, int64_t t) {
  int i, j, k;
  GridDims::split(uint32_t(t), uint32_t(e.x1 - e.x0), uint32_t(e.y1 - e.y0), i, j, k);
  return (int64_t(k) * d.ny + e.y0 + j) * d.nx + e.x0 + i;
}
/// The face of index t among an extent's faces (u | v | w, each x fastest): its component c and
/// index f in the component's array.
WB_HD WB_INLINE void extent_face(const GridDims& d, const GridExtent& e, int64_t t, int& c, int64_t& f) {
  const int64_t bx = e.x1 - e.x0, by = e.y1 - e.y0;
  const int64_t nu = (bx + 1) * by * e.layers, nv = bx * (by + 1) * e.layers;
  c = t < nu ? 0 : (t < nu + nv ? 1 : 2);
  const int64_t s = c == 0 ? t : (c == 1 ? t - nu : t - nu - nv);
  const int ex = int(bx) + (c == 0), ey = int(by) + (c == 1);  // the box's faces along x and y
  int i, j, k;
  GridDims::split(uint32_t(s), uint32_t(ex), uint32_t(ey), i, j, k);
  f = (int64_t(k) * (d.ny + (c == 1)) + e.y0 + j) * (d.nx + (c == 0)) + e.x0 + i;
}

/// The pressure system A p = b on liquid cells (Batty et al. 2007 face fractions):
/// (A p)_i = sum_f theta_f (p_i - p_nb(f)), p = 0 outside liquid, theta = open fraction.
struct PoissonView {
  GridDims d;
  const uint8_t* cls;      ///< CellClass per cell
  const float* theta[3];   ///< open face fractions per component (u, v, w)
  const GridExtent* extent = nullptr;  ///< the cells the solver visits (device); null: every cell
};

/// Everything the grid kernels read and write, by value.
struct GridView {
  GridDims d;
  float* vel[3];         ///< MAC velocity u, v, w (cells/s)
  float* theta[3];       ///< open fraction of each face, 0 = closed (solid), 1 = open
  float* solid_vel[3];   ///< velocity of the solid part of each face (bristles; 0 for dried paint)
  uint8_t* cls;          ///< CellClass per cell
  uint8_t* fluid[3];     ///< 1 where the face is open and touches a liquid cell (set by classify)
  float* pressure;       ///< projected pressure (scaled so that u -= grad p), cells^2/s
  const GridExtent* extent = nullptr;  ///< the layers the stages visit (device); null: the whole window
  WB_HD PoissonView poisson() const {
    PoissonView p;
    p.d = d;
    p.cls = cls;
    p.theta[0] = theta[0];
    p.theta[1] = theta[1];
    p.theta[2] = theta[2];
    p.extent = extent;
    return p;
  }
};

/// Volume flux through face f of component c per unit face area, cells/s: the fluid part
/// moves at the grid velocity, the bristle-covered part with the bristles (theta u + (1 - theta)
/// u_solid). The projection zeroes its divergence; paint advection moves paint with it.
WB_HD WB_INLINE float face_mixture_velocity(const GridView& g, int c, int64_t f) {
  const float t = g.theta[c][f];
  return t * g.vel[c][f] + (1.f - t) * g.solid_vel[c][f];
}

}  // namespace wb
