// Grid step (paper §4.2): resting paint stays still, a moving plate pushes paint and piles
// it up, dried cells never move, drying makes cells solid, the viscous solve converges for the
// stiffest paint, and advection keeps mass exactly in a pushed stroke and a swirl.
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <utility>

#include "backend_fixture.h"
#include "core/exec/memory.h"
#include "core/grid/rheology.h"
#include "grid/grid_test_util.h"

namespace wb::test {

class GridStepTest : public BackendTest {};

/// What paint advected through a fixed flow kept: the worst relative change of its mass and the
/// lowest and highest density over the steps.
struct FlowRun {
  double worst = 0;
  float lo = 0.f, hi = 0.f;
};

/// Advects g's paint `steps` steps through the face velocities (u, v, w), set again before each
/// step; `each(step)` sees g after each.
FlowRun advect_in_flow(Grid& g, const std::vector<float>& u, const std::vector<float>& v, const std::vector<float>& w,
                       float dt, int steps, const std::function<void(int)>& each) {
  const double m0 = sum(host_density(g));
  FlowRun run;
  for (int s = 0; s < steps; ++s) {
    g.window().velocity(0).copy_from_host(u);
    g.window().velocity(1).copy_from_host(v);
    g.window().velocity(2).copy_from_host(w);
    g.classify();
    g.advect(dt);
    g.read_record();
    const auto rho = host_density(g);
    run.worst = std::max(run.worst, std::fabs(sum(rho) - m0) / m0);
    for (float r : rho) {
      run.lo = std::min(run.lo, r);
      run.hi = std::max(run.hi, r);
    }
    each(s);
  }
  return run;
}

TEST_F(GridStepTest, StillPaintLayerStaysStill) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  Grid g(canvas, GridParams{}, Int3{48, 48, 16}, Int3{64, 64, 0});
  // A 6-cell layer with a thinner 3-cell region and a partly filled top: gravity acts.
  paint_cells(g, [](int i, int j, int k) {
    const int h = (i > 20 && i < 30) ? 3 : 6;
    return k < h ? 1.f : (k == h ? 0.3f : 0.f);
  });
  const auto rho0 = host_density(g);
  const float dt = g.params().dt;
  int iterations = 0;
  for (int s = 0; s < 100; ++s) {
    g.step(dt);
    g.read_record();
    iterations = std::max(iterations, g.stats().viscosity_iterations);
  }
  std::printf("[ still ] most CG iterations in a step: %d\n", iterations);
  const float speed = g.max_fluid_speed();
  EXPECT_LT(speed * dt, 1e-4f) << "spurious current " << speed << " cells/s";
  const auto rho1 = host_density(g);
  double change = 0;
  for (size_t i = 0; i < rho0.size(); ++i) change = std::max(change, double(std::fabs(rho1[i] - rho0[i])));
  // The 3-cell step (5.9 Pa at its foot) is below the yield stress of oil-0.2 paint (60 Pa): it
  // creeps only at the regularised viscosity tau_y m = 6e5 Pa s, about 1e-4 cells in 1.7 s.
  EXPECT_LT(change, 1e-3);
}

TEST_F(GridStepTest, PlatePushesPaintAndPilesItUp) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  GridParams p;
  Grid g(canvas, p, Int3{64, 32, 24}, Int3{32, 32, 0});
  const GridDims d = g.dims();
  // Block of paint x in [20, 44), y in [8, 24), 5 cells tall.
  paint_cells(g, [](int i, int j, int k) { return (i >= 20 && i < 44 && j >= 8 && j < 24 && k < 5) ? 1.f : 0.f; });
  const auto rho0 = host_density(g);
  const Vec3 c0 = centroid(d, rho0);
  HostBristles br(device_, d.cells());
  const float speed = 30.f, dt = p.dt;  // half a cell per step
  float x0 = 14.f;
  auto height_in_front = [&](const std::vector<float>& rho, float plate_front) {
    int best = 0;
    for (int j = 10; j < 22; ++j)
      for (int i = int(plate_front); i < std::min(int(plate_front) + 6, d.nx); ++i) {
        int h = 0;
        for (int k = 0; k < d.nz; ++k)
          if (rho[size_t(d.cell(i, j, k))] >= 0.5f) h = k + 1;
        best = std::max(best, h);
      }
    return best;
  };
  const int h0 = height_in_front(rho0, 20.f);
  const double m0 = sum(rho0);
  for (int s = 0; s < 40; ++s) {
    br.plate(d, x0, x0 + 2.f, 4, 28, 14, speed);
    g.set_bristles(br.field());
    g.step(dt);
    x0 += speed * dt;
  }
  const auto rho1 = host_density(g);
  const Vec3 c1 = centroid(d, rho1);
  EXPECT_GT(c1.x, c0.x + 2.f) << "paint should move with the plate";
  const int h1 = height_in_front(rho1, x0 + 2.f);
  EXPECT_GT(h1, h0) << "paint should pile up in front of the plate";
  EXPECT_NEAR(sum(rho1), m0, 1e-4 * m0);
}

// A cell liquid by its particles alone has the rheology of their paint (JointOil): the particles'
// rasterised oil joins the grid's, mass-weighted. Without it such a cell read the grid's empty
// oil, 0, and had the stiffest paint's viscosity whatever the brush carried.
TEST_F(GridStepTest, ParticlePaintHasItsOwnOilsRheology) {
  TileStore canvas(device_, CanvasDims{128, 128, 32});
  GridParams p;
  Grid g(canvas, p, Int3{24, 24, 12}, Int3{16, 16, 0});
  const GridDims d = g.dims();
  paint_cells(g, [](int, int, int k) { return k < 2 ? 1.f : 0.f; }, 0.1f);  // a stiff grid layer
  std::vector<float> density(size_t(d.cells()), 0.f), oil(size_t(d.cells()), 0.f);
  for (int k = 1; k < 4; ++k)
    for (int j = 8; j < 16; ++j)
      for (int i = 8; i < 16; ++i) {
        density[size_t(d.cell(i, j, k))] = 1.f;
        oil[size_t(d.cell(i, j, k))] = 0.7f;  // volume 1 of oil-0.7 paint
      }
  DeviceBuffer<float> pd(device_, density.size()), po(device_, oil.size());
  pd.copy_from_host(density);
  po.copy_from_host(oil);
  const HerschelBulkley stiff{p.yield_stress_stiff, p.consistency_stiff, p.flow_index_stiff};
  const HerschelBulkley oily{p.yield_stress_oily, p.consistency_oily, p.flow_index_oily};
  auto at_rest = [&](float o) { return apparent_viscosity(rheology_at_oil(o, stiff, oily), 0.f, p.regularisation); };
  auto mu_of = [&](const float* particle_oil) {
    g.set_particle_density(pd.data(), particle_oil);
    g.classify();
    g.rheology();
    return g.apparent_viscosity().to_host();
  };
  const auto mu = mu_of(po.data());
  // Particles alone: oil 0.7; over the grid layer (k = 1: grid 1 at oil 0.1 and particles 1 at
  // 0.7): the mean, 0.4; the grid alone (k = 0): 0.1.
  EXPECT_FLOAT_EQ(mu[size_t(d.cell(12, 12, 3))], at_rest(0.7f));
  EXPECT_NEAR(mu[size_t(d.cell(12, 12, 1))], at_rest(0.4f), 1e-5f * at_rest(0.4f));
  EXPECT_FLOAT_EQ(mu[size_t(d.cell(12, 12, 0))], at_rest(0.1f));
  EXPECT_LT(at_rest(0.7f), 0.01f * at_rest(0.f)) << "oily paint is far softer than the stiffest";
  // The grid's oil alone (no particle oil given): the particle cell reads the empty cell's.
  EXPECT_FLOAT_EQ(mu_of(nullptr)[size_t(d.cell(12, 12, 3))], at_rest(0.f));
}

// A block of the stiffest paint (oil 0: about 3e6 Pa s, nu dt about 1e9 cells^2) held by nothing,
// in air above a paint layer: free slip on every side, so the viscous matrix is the identity plus
// a huge Laplacian whose null space (the block moving as one) only the identity holds. In float
// that identity is lost to rounding, the matrix turns indefinite and CG diverged (residual 1e6,
// faces at 1e5 cells/s); in double the solve converges and the block falls as a body does.
TEST_F(GridStepTest, FloatingStiffPaintSolveConverges) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  GridParams p;
  Grid g(canvas, p, Int3{48, 32, 24}, Int3{32, 32, 0});
  paint_cells(
      g,
      [](int i, int j, int k) {
        return (k >= 10 && k < 16 && j >= 10 && j < 20 && i >= 18 && i < 28) || (k < 2 && i >= 8 && i < 40) ? 1.f
                                                                                                             : 0.f;
      },
      0.f);
  const double m0 = sum(host_density(g));
  const float fall = p.gravity * p.dt;  // cells/s gained in a step of free fall
  for (int s = 0; s < 3; ++s) {
    g.step(p.dt);
    g.read_record();
    const GridStats& st = g.stats();
    std::printf("[ floating ] step %d: %d faces, %d CG iterations, residual %.2e, fastest face %.3g cells/s\n", s,
                st.viscosity_faces, st.viscosity_iterations, st.viscosity_residual, double(g.max_fluid_speed()));
    EXPECT_LT(st.viscosity_iterations, p.viscosity_max_iterations) << "step " << s;
    EXPECT_LE(st.viscosity_residual, double(p.viscosity_tolerance)) << "step " << s;
    EXPECT_LE(g.max_fluid_speed(), 1.5f * fall * float(s + 1)) << "no faster than free fall, step " << s;
  }
  EXPECT_NEAR(sum(host_density(g)), m0, 1e-4 * m0);
}

// The same scene as below on the CPU and on this backend (a GPU), in lockstep: a plate sweeps a
// paint layer with particles in flight above it for 10 steps. Sums run in another order on each,
// and the regularised viscosity is steep near the yield stress (a rounding's change of strain rate
// moves it by decades), so the two part by rounding: the paint agrees to 10^-3 of its mass with
// the same top (of more than a trace) after every stage, the liquid's velocity to 5 % of its fastest face, first with
// the stages called one by one on the whole window, then with the step (bounded to the paint's
// layers).
// Before the viscous solve ran in double, a floating block's solve diverged on each backend to
// its own values (faces at 10^5 to 10^6 cells/s) and the paint parted in the first step.
TEST_F(GridStepTest, SameStagesOnCpuAndThisBackend) {
  if (device_.is_cpu()) GTEST_SKIP() << "run with WB_DEVICE=cuda to compare the CUDA backend with the CPU";
  struct Side {
    TileStore canvas;
    Grid g;
    HostBristles br;
    DeviceBuffer<float> flight;
    Side(const Device& d, const GridParams& p)
        : canvas(d, CanvasDims{256, 256, 64}), g(canvas, p, Int3{48, 32, 24}, Int3{32, 32, 0}),
          br(d, g.dims().cells()), flight(d, size_t(g.dims().cells())) {}
  };
  GridParams p;
  for (const bool whole_step : {false, true}) {
    Side a(device_, p), b(Device(DeviceType::CPU), p);
    const GridDims d = a.g.dims();
    std::vector<float> flight(size_t(d.cells()), 0.f);
    for (int k = 10; k < 16; ++k)
      for (int j = 10; j < 20; ++j)
        for (int i = 18; i < 28; ++i) flight[size_t(d.cell(i, j, k))] = 1.f;
    for (Side* x : {&a, &b}) {
      paint_cells(x->g, [](int i, int j, int k) {
        return (i >= 20 && i < 26 && j >= 12 && j < 18 && k < 6) || (k < 2 && i >= 8 && i < 40) ? 1.f : 0.f;
      });
      x->flight.copy_from_host(flight);
    }
    // The paint's top: the layers holding more than a trace (kTraceDensity, the grid's own
    // measure of where paint is); a trace's layer is decided by a rounding of a velocity.
    auto top_of = [&](const std::vector<float>& rho) {
      int top = 0;
      for (int64_t c = 0; c < d.cells(); ++c)
        if (rho[size_t(c)] > kTraceDensity) top = std::max(top, int(c / (int64_t(d.nx) * d.ny)) + 1);
      return top;
    };
    // The densest cell at or above layer k (what a differing top holds).
    auto densest_from = [&](const std::vector<float>& rho, int k) {
      float m = 0.f;
      for (int64_t c = int64_t(k) * d.nx * d.ny; c < d.cells(); ++c) m = std::max(m, rho[size_t(c)]);
      return m;
    };
    std::string first;  // the first stage whose results part
    double worst_paint = 0, worst_v = 0;  // relative to the paint's mass and the fastest face (CPU)
    auto compare = [&](int s, const char* stage) {
      const auto ra = host_density(a.g), rb = host_density(b.g);
      double diff = 0, mass = 0;
      for (size_t i = 0; i < ra.size(); ++i) {
        diff += std::fabs(double(ra[i]) - double(rb[i]));
        mass += double(rb[i]);
      }
      // Velocities on the faces fluid on both (the liquid's; what air faces hold is not read
      // before the next extrapolation writes them, and the layers above the paint keep theirs).
      float dv = 0.f, vmax = 1.f;
      for (int c = 0; c < 3; ++c) {
        const auto va = a.g.window().velocity(c).to_host(), vb = b.g.window().velocity(c).to_host();
        std::vector<uint8_t> fa(va.size()), fb(vb.size());
        mem::copy_to_host(a.g.device(), fa.data(), a.g.view().fluid[c], fa.size());
        mem::copy_to_host(b.g.device(), fb.data(), b.g.view().fluid[c], fb.size());
        for (size_t i = 0; i < va.size(); ++i) {
          if (!fa[i] || !fb[i]) continue;
          dv = std::max(dv, std::fabs(va[i] - vb[i]));
          vmax = std::max(vmax, std::fabs(vb[i]));
        }
      }
      const double fastest = vmax;
      worst_paint = std::max(worst_paint, diff / mass);
      worst_v = std::max(worst_v, double(dv) / fastest);
      const bool parted = diff > 1e-3 * mass || top_of(ra) != top_of(rb) || !(double(dv) <= 0.05 * fastest);
      if (parted && first.empty()) {
        first = std::string(stage) + " of step " + std::to_string(s);
        const int low = std::min(top_of(ra), top_of(rb));
        std::printf("[ backends ] %s: parted at %s: paint L1 %.3g of %.3g, top %d vs %d (cpu), densest cell from "
                    "layer %d %.3g vs %.3g (cpu), |dv| %.3g of %.3g cells/s\n",
                    whole_step ? "step" : "stages", first.c_str(), diff, mass, top_of(ra), top_of(rb), low,
                    double(densest_from(ra, low)), double(densest_from(rb, low)), double(dv), fastest);
        for (Side* x : {&a, &b}) {
          x->g.read_record();
          const GridStats& st = x->g.stats();
          std::printf("[ backends ] %s: viscous solve: %d faces, %d iterations, residual %.3g\n",
                      x == &a ? "this backend" : "cpu", st.viscosity_faces, st.viscosity_iterations,
                      st.viscosity_residual);
        }
      }
    };
    float x0 = 4.f;
    for (int s = 0; s < 14; ++s) {
      for (Side* x : {&a, &b}) {
        x->br.plate(d, x0, x0 + 2.f, 4, 28, 6, 30.f);
        x->g.set_bristles(x->br.field());
        x->g.set_particle_density(s < 10 ? x->flight.data() : nullptr);
      }
      x0 += 0.5f;
      if (whole_step) {
        for (Side* x : {&a, &b}) x->g.step(p.dt);
        compare(s, "step");
        continue;
      }
      const std::pair<const char*, std::function<void(Grid&)>> stages[] = {
          {"classify", [](Grid& g) { g.classify(); }},
          {"advect", [&](Grid& g) { g.advect(p.dt); }},
          {"classify after advection", [](Grid& g) { g.classify(); }},
          {"rheology", [](Grid& g) { g.rheology(); }},
          {"forces", [&](Grid& g) { g.add_external_forces(p.dt); }},
          {"viscosity", [&](Grid& g) { g.apply_viscosity(p.dt); }},
          {"project", [&](Grid& g) { g.project(p.dt); }},
          {"dry", [&](Grid& g) { g.dry(p.dt); }},
      };
      for (const auto& [name, fn] : stages) {
        fn(a.g);
        fn(b.g);
        compare(s, name);
      }
    }
    std::printf("[ backends ] %s: worst paint L1 %.2g of the mass, worst velocity %.2g of the fastest face\n",
                whole_step ? "step" : "stages", worst_paint, worst_v);
    EXPECT_TRUE(first.empty()) << (whole_step ? "step: " : "stages: ") << first;
  }
}

// The stages after the joint fields visit only the layers that hold paint or particles
// (GridExtent). A plate sweeps a paint layer with a 6-cell column on it; for the first 10 steps
// particles in flight fill layers 10 to 16 above the column (their rasterised density joins the
// grid's), then they are gone and the extent falls to the paint's. After every step the state is
// what a full-window pass gives: the classes, open fractions and fluid faces equal a
// classification of the whole window, and the pressure, the apparent viscosity and the
// projection's right-hand side are 0 in every cell without liquid (the layers the last step used
// are visited once more to clear them). The thin films, which move paint after the projection
// (Grid::flow_film) and so after the classes were made, are off: the classes made again would
// see their paint.
TEST_F(GridStepTest, StagesVisitOnlyThePaintsLayersAndLeaveTheRestAsTheWholeWindowWould) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  GridParams p;
  p.film_max = 0.f;
  Grid g(canvas, p, Int3{48, 32, 24}, Int3{32, 32, 0});
  const GridDims d = g.dims();
  paint_cells(g, [](int i, int j, int k) {
    return (i >= 20 && i < 26 && j >= 12 && j < 18 && k < 6) || (k < 2 && i >= 8 && i < 40) ? 1.f : 0.f;
  });
  std::vector<float> flight(size_t(d.cells()), 0.f);
  for (int k = 10; k < 16; ++k)
    for (int j = 10; j < 20; ++j)
      for (int i = 18; i < 28; ++i) flight[size_t(d.cell(i, j, k))] = 1.f;
  DeviceBuffer<float> particle_density(device_, size_t(d.cells()));
  particle_density.copy_from_host(flight);
  HostBristles br(device_, d.cells());
  auto copy_u8 = [&](const uint8_t* src, int64_t n) {
    std::vector<uint8_t> out(static_cast<size_t>(n));
    mem::copy_to_host(device_, out.data(), src, size_t(n));
    return out;
  };
  auto copy_f = [&](const float* src, int64_t n) {
    std::vector<float> out(static_cast<size_t>(n));
    mem::copy_to_host(device_, out.data(), src, size_t(n) * sizeof(float));
    return out;
  };
  int first_layers = 0, last_layers = 0, first_box = 0, last_box = 0, checked = 0;
  std::string tops;  // the paint's top / the layers visited, by step
  float x0 = 4.f;
  for (int s = 0; s < 30; ++s) {
    br.plate(d, x0, x0 + 2.f, 4, 28, 6, 30.f);
    g.set_bristles(br.field());
    g.set_particle_density(s < 10 ? particle_density.data() : nullptr);
    g.step(p.dt);
    x0 += 0.5f;
    GridExtent e{};
    g.extent().copy_to_host(&e, 1);
    if (s == 0) first_layers = e.layers, first_box = (e.x1 - e.x0) * (e.y1 - e.y0);
    last_layers = e.layers;
    last_box = (e.x1 - e.x0) * (e.y1 - e.y0);
    // The extent covers the paint and the layer above it, and no more once the first step
    // has cleared the window.
    const auto rho = host_density(g);
    int top = s < 10 ? 16 : 0;
    for (int64_t c = 0; c < d.cells(); ++c)
      if (rho[size_t(c)] > 0.f) top = std::max(top, int(c / (int64_t(d.nx) * d.ny)) + 1);
    tops += " " + std::to_string(top) + "/" + std::to_string(e.layers);
    if (s == 29) {
      double high = 0.0;
      for (int64_t c = int64_t(d.nx) * d.ny * 10; c < d.cells(); ++c) high = std::max(high, double(rho[size_t(c)]));
      std::printf("[ extent ] densest cell above layer 10 at the end: %.3g\n", high);
    }
    ASSERT_GE(e.layers, std::min(d.nz, top + 1)) << "step " << s;
    if (s > 1 && s != 10) ASSERT_LE(e.layers, top + 2) << "step " << s;
    if (s == 9) EXPECT_GE(e.layers, 17);
    GridView v = g.view();
    const auto cls = copy_u8(v.cls, d.cells());
    std::vector<std::vector<float>> theta, solid;
    std::vector<std::vector<uint8_t>> fluid;
    for (int c = 0; c < 3; ++c) {
      theta.push_back(copy_f(v.theta[c], d.faces(c)));
      solid.push_back(copy_f(v.solid_vel[c], d.faces(c)));
      fluid.push_back(copy_u8(v.fluid[c], d.faces(c)));
    }
    const auto pressure = g.pressure().to_host(), mu = g.apparent_viscosity().to_host(), rhs = g.rhs().to_host();
    int liquid_above = 0;
    for (int64_t c = 0; c < d.cells(); ++c) {
      if (cls[size_t(c)] == kCellLiquid) {
        liquid_above += c >= int64_t(d.nx) * d.ny * e.layers;
        continue;
      }
      ASSERT_EQ(pressure[size_t(c)], 0.f) << "step " << s << " cell " << c;
      ASSERT_EQ(mu[size_t(c)], 0.f) << "step " << s << " cell " << c;
      ASSERT_EQ(rhs[size_t(c)], 0.f) << "step " << s << " cell " << c;
    }
    EXPECT_EQ(liquid_above, 0) << "step " << s;
    // As the step would have made them without the extent: the classes of its cells and the
    // layer above, the fractions of their faces, and the fluid flags everywhere (none outside).
    // Classes and fractions elsewhere are the advection's or an earlier step's: nothing reads them.
    g.classify();
    auto in_extent = [](auto v, int64_t n, auto index) {
      decltype(v) out;
      for (int64_t t = 0; t < n; ++t) out.push_back(v[size_t(index(t))]);
      return out;
    };
    auto cell_at = [&](int64_t t) { return extent_cell(d, e, t); };
    EXPECT_EQ(in_extent(copy_u8(v.cls, d.cells()), e.classes, cell_at), in_extent(cls, e.classes, cell_at))
        << "step " << s;
    std::vector<int64_t> face_index[3];
    for (int64_t t = 0; t < e.faces; ++t) {
      int c;
      int64_t f;
      extent_face(d, e, t, c, f);
      face_index[c].push_back(f);
    }
    for (int c = 0; c < 3; ++c) {
      auto at = [&](int64_t t) { return face_index[c][size_t(t)]; };
      const int64_t n = int64_t(face_index[c].size());
      EXPECT_EQ(in_extent(copy_f(v.theta[c], d.faces(c)), n, at), in_extent(theta[size_t(c)], n, at))
          << "step " << s << " component " << c;
      EXPECT_EQ(in_extent(copy_f(v.solid_vel[c], d.faces(c)), n, at), in_extent(solid[size_t(c)], n, at))
          << "step " << s << " component " << c;
      EXPECT_EQ(copy_u8(v.fluid[c], d.faces(c)), fluid[size_t(c)]) << "step " << s << " component " << c;
    }
    ++checked;
  }
  std::printf("[ extent ] layers visited: %d at the first step, %d at the last (of %d); columns %d, %d (of %d)\n",
              first_layers, last_layers, d.nz, first_box, last_box, d.nx * d.ny);
  std::printf("[ extent ] paint's top / layers visited by step:%s\n", tops.c_str());
  EXPECT_EQ(checked, 30);
  EXPECT_EQ(first_layers, d.nz) << "the first step visits every layer once";
  EXPECT_EQ(first_box, d.nx * d.ny) << "and every column";
  // The layer of paint spans x in [8, 40) and every row; the stroke spreads it a little.
  EXPECT_LE(last_box, 40 * d.ny) << "the extent follows the paint across";
  EXPECT_LT(last_layers, 12) << "the extent follows the paint down when the particles are gone";
}

TEST_F(GridStepTest, AfterAWindowMoveNoFaceOutsideTheLiquidIsFluid) {
  // The classes, flags and pressure are not shifted with the window (the paint and velocities
  // are): after a move the old liquid's cells are where the array held them, which the last
  // step's box (`dirty_box`) covers. A blob of paint stepped, the window moved under it by 12
  // cells, then stepped again: every step's fluid flags equal a whole-window classification's,
  // no non-liquid cell keeps a pressure, and the step after the move visits the two blobs' box,
  // not the window.
  TileStore canvas(device_, CanvasDims{256, 256, 32});
  GridParams p;
  Grid g(canvas, p, Int3{48, 32, 16}, Int3{32, 32, 0});
  const GridDims d = g.dims();
  paint_cells(g, [](int i, int j, int k) { return i >= 4 && i < 14 && j >= 10 && j < 20 && k < 5 ? 1.f : 0.f; });
  auto copy_u8 = [&](const uint8_t* src, int64_t n) {
    std::vector<uint8_t> out(static_cast<size_t>(n));
    mem::copy_to_host(device_, out.data(), src, size_t(n));
    return out;
  };
  int columns_after_move = 0;
  for (int s = 0; s < 12; ++s) {
    if (s == 4) ASSERT_TRUE(g.move_window(Int3{44, 32, 0}));
    g.step(p.dt);
    GridExtent e{};
    g.extent().copy_to_host(&e, 1);
    if (s == 4) columns_after_move = (e.x1 - e.x0) * (e.y1 - e.y0);
    GridView v = g.view();
    const auto cls = copy_u8(v.cls, d.cells());
    std::vector<std::vector<uint8_t>> fluid;
    for (int c = 0; c < 3; ++c) fluid.push_back(copy_u8(v.fluid[c], d.faces(c)));
    const auto pressure = g.pressure().to_host();
    for (int64_t c = 0; c < d.cells(); ++c)
      if (cls[size_t(c)] != kCellLiquid) ASSERT_EQ(pressure[size_t(c)], 0.f) << "step " << s << " cell " << c;
    g.classify();  // the whole window
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(copy_u8(v.fluid[c], d.faces(c)), fluid[size_t(c)]) << "step " << s << " component " << c;
  }
  // The blob's 10 x 10 columns before and after the move, 12 apart, a cell around: 24 x 12.
  EXPECT_LE(columns_after_move, 26 * 14) << "the step after a move visits the old and new liquid's columns";
  EXPECT_GT(columns_after_move, 22 * 10);
}

TEST_F(GridStepTest, DriedCellsNeverMove) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  GridParams p;
  Grid g(canvas, p, Int3{64, 32, 24}, Int3{0, 0, 0});
  const GridDims d = g.dims();
  // Wet block in front of a dried wall (x in [40, 44)) and a dried floor crust under it.
  Fields f = empty_fields(g);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) {
        const size_t c = size_t(d.cell(i, j, k));
        const bool wall = i >= 40 && i < 44 && j >= 4 && j < 28 && k < 8;
        const bool crust = k == 0 && i >= 16 && i < 40 && j >= 4 && j < 28;
        const bool wet = i >= 20 && i < 40 && j >= 8 && j < 24 && k >= 1 && k < 6;
        if (wall || crust) {
          f[0][c] = 0.9f;
          f[3][c] = 1.f;
          f[5][c] = 1.f;
        } else if (wet) {
          f[0][c] = 1.f;
          f[1][c] = 1.f;
          f[4][c] = 0.8f;
        }
      }
  g.window().paint().from_host(f);
  HostBristles br(device_, d.cells());
  float x0 = 14.f;
  for (int s = 0; s < 40; ++s) {
    br.plate(d, x0, x0 + 2.f, 6, 26, 12, 30.f);
    g.set_bristles(br.field());
    g.step(p.dt);
    x0 += 0.5f;
  }
  const auto after = g.window().paint().to_host();
  int dried = 0;
  for (size_t c = 0; c < after[0].size(); ++c) {
    if (f[5][c] < 1.f) continue;
    ++dried;
    for (int q = 0; q < kPaintFieldCount; ++q) ASSERT_EQ(after[size_t(q)][c], f[size_t(q)][c]) << "field " << q;
  }
  EXPECT_GT(dried, 500);
  // The wet paint did move (the test is not vacuous).
  EXPECT_GT(centroid(d, after[0]).x, centroid(d, f[0]).x + 0.2f);
}

TEST_F(GridStepTest, DryingMakesPaintSolid) {
  TileStore canvas(device_, CanvasDims{128, 128, 64});
  GridParams p;
  p.dry_rate = 3.f;  // fully dry in a third of a second
  Grid g(canvas, p, Int3{32, 32, 16}, Int3{0, 0, 0});
  paint_cells(g, [](int, int, int k) { return k < 4 ? 1.f : 0.f; });
  g.dry(0.1f);
  const auto dry1 = g.window().paint().dryness.to_host();
  const GridDims d = g.dims();
  EXPECT_NEAR(dry1[size_t(d.cell(3, 3, 1))], 0.3f, 1e-6f);
  EXPECT_EQ(dry1[size_t(d.cell(3, 3, 8))], 0.f);  // no paint, no dryness
  for (int s = 0; s < 4; ++s) g.dry(0.1f);
  g.classify();
  std::vector<uint8_t> cls(size_t(d.cells()));
  mem::copy_to_host(device_, cls.data(), g.view().cls, cls.size());
  EXPECT_EQ(cls[size_t(d.cell(3, 3, 1))], kCellSolid);
  EXPECT_EQ(cls[size_t(d.cell(3, 3, 8))], kCellAir);
}

TEST_F(GridStepTest, LetItDryMakesTheWholeCanvasSolid) {
  TileStore canvas(device_, CanvasDims{128, 128, 64});
  Grid g(canvas, GridParams{}, Int3{32, 32, 16}, Int3{8, 8, 0});
  paint_cells(g, [](int, int, int k) { return k < 4 ? 1.f : 0.f; });
  g.window().flush();
  canvas.dry_all();
  g.window().reload();
  g.classify();
  const GridDims d = g.dims();
  std::vector<uint8_t> cls(size_t(d.cells()));
  mem::copy_to_host(device_, cls.data(), g.view().cls, cls.size());
  for (int k = 0; k < 4; ++k) EXPECT_EQ(cls[size_t(d.cell(5, 7, k))], kCellSolid);
  EXPECT_EQ(cls[size_t(d.cell(5, 7, 4))], kCellAir);
}

TEST_F(GridStepTest, PaintDriesEverywhereWindowOrNot) {
  TileStore canvas(device_, CanvasDims{256, 128, 32});
  // A 4-cell layer over x in [0, 256), y in [32, 80): 48 tiles, most of them outside the window.
  for (int tx = 0; tx < canvas.tiles_x(); ++tx)
    for (int ty = 2; ty < 5; ++ty) {
      TileData t = canvas.read_tile(ty * canvas.tiles_x() + tx);
      t.tile_x = tx;
      t.tile_y = ty;
      for (int z = 0; z < 4; ++z)
        for (int c = 0; c < kTileSize * kTileSize; ++c) {
          const size_t at = size_t(z) * kTileSize * kTileSize + size_t(c);
          t.density[at] = 1.f;
          t.pigment_r[at] = encode_unorm16(0.5f);
        }
      canvas.write_tile(t);
    }
  GridParams p;
  p.dry_rate = 0.6f;  // per second: solid (0.95) after about 1.6 s
  // The window spans x in [104, 136): tiles 6 and 8 lie partly inside it.
  Grid g(canvas, p, Int3{32, 32, 16}, Int3{104, 40, 0});
  for (int s = 0; s < 60; ++s) g.step(p.dt);  // 1 s
  const float after_1s = 0.6f;
  EXPECT_NEAR(canvas.read_cell(20, 50, 1).dryness, after_1s, 1e-4f) << "far from the window";
  EXPECT_NEAR(canvas.read_cell(100, 50, 1).dryness, after_1s, 1e-4f) << "in a tile the window covers in part";
  EXPECT_EQ(canvas.read_cell(20, 50, 10).dryness, 0.f) << "air does not dry";
  const auto win = g.window().paint().dryness.to_host();
  EXPECT_NEAR(win[size_t(g.dims().cell(16, 10, 1))], after_1s, 1e-4f) << "in the window";
  // Move away: the scatter keeps the partly covered tiles right on both sides of the old edge.
  g.move_window(Int3{8, 40, 0});
  EXPECT_NEAR(canvas.read_cell(100, 50, 1).dryness, after_1s, 1e-4f);
  EXPECT_NEAR(canvas.read_cell(120, 50, 1).dryness, after_1s, 1e-4f);
  EXPECT_NEAR(canvas.read_cell(140, 50, 1).dryness, after_1s, 1e-4f);
  for (int s = 0; s < 40; ++s) g.step(p.dt);  // 1.67 s: past the threshold everywhere
  EXPECT_EQ(canvas.read_cell(200, 50, 1).dryness, 1.f);
  g.classify();
  std::vector<uint8_t> cls(size_t(g.dims().cells()));
  mem::copy_to_host(device_, cls.data(), g.view().cls, cls.size());
  EXPECT_EQ(cls[size_t(g.dims().cell(5, 15, 1))], kCellSolid);
  // Back over paint that dried while the window was away: it arrives solid.
  g.move_window(Int3{200, 40, 0});
  g.classify();
  mem::copy_to_host(device_, cls.data(), g.view().cls, cls.size());
  EXPECT_EQ(cls[size_t(g.dims().cell(10, 15, 1))], kCellSolid);
}

TEST_F(GridStepTest, ViscousSolveConvergesForTheStiffestPaint) {
  TileStore canvas(device_, CanvasDims{128, 128, 64});
  GridParams p;
  p.yield_stress_stiff = 1e4f;  // the table's top: unyielded mu = tau_y m = 1e6 Pa s, nu dt ~ 4e8 cells^2
  p.consistency_stiff = 1e5f;
  Grid g(canvas, p, Int3{32, 32, 16}, Int3{0, 0, 0});
  paint_cells(g, [](int, int, int k) { return k < 10 ? 1.f : 0.f; }, /*oil=*/0.f);
  g.classify();
  auto random_velocity = [&] {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-100.f, 100.f);
    for (int c = 0; c < 3; ++c) {
      std::vector<float> v(size_t(g.dims().faces(c)));
      for (auto& x : v) x = u(rng);
      g.window().velocity(c).copy_from_host(v);
    }
    g.rheology();
  };
  random_velocity();
  const float before = g.max_fluid_speed();
  // The device runs the iterations and tests their convergence (LaunchLoop): the solve makes no
  // host read, the first (which allocates its vectors) as every other.
  const int64_t first = mem::host_reads();
  g.apply_viscosity(p.dt);
  const int64_t first_reads = mem::host_reads() - first;
  std::vector<float> solved[3];
  for (int c = 0; c < 3; ++c) solved[c] = g.window().velocity(c).to_host();
  random_velocity();
  const int64_t reads = mem::host_reads();
  g.apply_viscosity(p.dt);
  const int64_t solve_reads = mem::host_reads() - reads;
  for (int c = 0; c < 3; ++c) EXPECT_EQ(g.window().velocity(c).to_host(), solved[c]) << "the same solve, one answer";
  g.read_record();
  const float after = g.max_fluid_speed();
  EXPECT_TRUE(std::isfinite(after));
  EXPECT_LE(g.stats().viscosity_residual, p.viscosity_tolerance);
  EXPECT_LT(g.stats().viscosity_iterations, p.viscosity_max_iterations);
  EXPECT_GT(g.stats().viscosity_faces, 3 * 30 * 30 * 9);
  EXPECT_LT(after, 0.5f * before);  // a no-slip floor and a random field: diffusion damps it
  const int it = g.stats().viscosity_iterations;
  EXPECT_EQ(first_reads, 0) << it << " iterations";
  EXPECT_EQ(solve_reads, 0);
  std::printf("[ viscosity ] stiffest paint: %d faces, %d CG iterations, residual %.2e, %lld host reads (%lld the "
              "first solve)\n",
              g.stats().viscosity_faces, it, g.stats().viscosity_residual, static_cast<long long>(solve_reads),
              static_cast<long long>(first_reads));
}

TEST_F(GridStepTest, AdvectionKeepsMassWithoutAnyCorrection) {
  TileStore canvas(device_, CanvasDims{256, 256, 64});
  GridParams p;
  Grid g(canvas, p, Int3{64, 32, 24}, Int3{32, 32, 0});
  const GridDims d = g.dims();
  paint_cells(g, [](int i, int j, int k) {
    return (i >= 20 && i < 44 && j >= 8 && j < 24) ? std::clamp(4.5f - float(k), 0.f, 1.f) : 0.f;
  });
  const auto rho0 = host_density(g);
  const double m0 = sum(rho0);
  const Vec3 c0 = centroid(d, rho0);
  HostBristles br(device_, d.cells());
  float x0 = 14.f;
  double worst = 0, lowest = 0;
  float most = 0.f;
  for (int s = 0; s < 60; ++s) {
    br.plate(d, x0, x0 + 2.f, 4, 28, 14, 30.f);
    g.set_bristles(br.field());
    const auto before = host_density(g);
    g.step(p.dt);
    const auto after = host_density(g);
    worst = std::max(worst, std::fabs(sum(after) - m0) / m0);
    for (float r : after) lowest = std::min(lowest, double(r));
    if (s > 0) EXPECT_NE(before, after) << "paint frozen at step " << s;  // step 0 has no velocity yet
    g.read_record();
    most = std::max(most, g.stats().advect_courant);
    x0 += 0.5f;
  }
  const Vec3 c1 = centroid(d, host_density(g));
  EXPECT_LT(worst, 1e-6) << "flux-form advection moves paint, never makes or loses it";
  EXPECT_GE(lowest, -1e-7) << "round-off only";
  EXPECT_GT(c1.x - c0.x, 0.5f) << "the plate pushes the paint";
  RecordProperty("mass_drift", std::to_string(worst));
  std::printf("[ mass ] plate stroke, 1 s: worst relative mass change %.2e, lowest density %.2e, "
              "centroid +%.2f cells, outflow Courant number at most %.2f\n",
              worst, lowest, c1.x - c0.x, most);
}

TEST_F(GridStepTest, APassCarriesPaintAsFarAsTheFlowAtAnySpeed) {
  // A block of paint carried along x and slowly along y, not at all along z (a stroke's drag),
  // from 2.5 to 40 cells a step: one pass along each axis that flows, whatever the speed, and the
  // paint lands where the flow takes it, its mass kept, no new extremum.
  for (const float U : {160.f, 640.f, 2560.f}) {
    TileStore canvas(device_, CanvasDims{512, 128, 16});
    GridParams p;
    Grid g(canvas, p, Int3{448, 48, 8}, Int3{0, 0, 0});
    const GridDims d = g.dims();
    paint_cells(g, [](int i, int j, int k) { return (i >= 8 && i < 20 && j >= 16 && j < 28 && k < 3) ? 1.f : 0.f; });
    const float dt = 1.f / 64.f, V = 20.f;  // U / 64 and 0.31 cells a step
    std::vector<float> u(size_t(d.nu()), U), v(size_t(d.nv()), V), w(size_t(d.nw()), 0.f);
    const Vec3 c0 = centroid(d, host_density(g));
    const int steps = 8;
    const FlowRun run = advect_in_flow(g, u, v, w, dt, steps, [&](int s) {
      EXPECT_EQ(g.stats().advect_passes, 2) << "step " << s << ": x and y, not z";
      EXPECT_NEAR(g.stats().advect_courant, U * dt, 1e-3f * U * dt);
    });
    const Vec3 c1 = centroid(d, host_density(g));
    EXPECT_LT(run.worst, 1e-6);
    EXPECT_GE(run.lo, 0.f);
    EXPECT_LE(run.hi, 1.f + 1e-5f) << "a uniform flow makes no new maximum";
    EXPECT_NEAR(c1.x - c0.x, U * dt * float(steps), 0.1f);
    EXPECT_NEAR(c1.y - c0.y, V * dt * float(steps), 0.05f);
    EXPECT_NEAR(c1.z - c0.z, 0.f, 1e-4f);
    std::printf("[ passes ] %.1f cells a step: x %.3f of %.3f cells, y %.3f of %.3f, 2 passes a step\n", U * dt,
                c1.x - c0.x, U * dt * float(steps), c1.y - c0.y, V * dt * float(steps));
  }
}

TEST_F(GridStepTest, PaintDrivenIntoAWallPilesUpWithoutNegativeDensity) {
  // A fast flow along x that stops at a wall of dried paint: the faces' speeds fall from 20 cells
  // a step to 0 over four cells. Paint runs into the wall and piles there (the projection, not
  // the advection, spreads it again); the paths never cross, so no density goes below 0 and the
  // mass is kept to round-off. The wall's paint stays put.
  TileStore canvas(device_, CanvasDims{128, 64, 16});
  GridParams p;
  Grid g(canvas, p, Int3{96, 32, 8}, Int3{0, 0, 0});
  const GridDims d = g.dims();
  const int wall = 60;
  paint_cells(g, [&](int i, int j, int k) {
    if (k >= 2 || j < 8 || j >= 24) return 0.f;
    if (i == wall) return 1.f;
    return (i >= 10 && i < 40) ? 0.6f : 0.f;
  });
  {
    // The wall column dried (solid): its faces carry no flow.
    auto f = g.window().paint().to_host();
    for (int k = 0; k < 2; ++k)
      for (int j = 8; j < 24; ++j) f[5][size_t(d.cell(wall, j, k))] = 1.f;
    g.window().paint().from_host(f);
  }
  const float dt = 1.f / 64.f, U = 1280.f;  // 20 cells a step
  std::vector<float> u(size_t(d.nu()), 0.f), v(size_t(d.nv()), 0.f), w(size_t(d.nw()), 0.f);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i <= d.nx; ++i)
        u[size_t(d.uidx(i, j, k))] = i <= wall - 4 ? U : (i < wall ? U * float(wall - i) / 4.f : 0.f);
  const double wall_mass = 16.0 * 2.0;
  const FlowRun run = advect_in_flow(g, u, v, w, dt, 6, [](int) {});
  const auto rho = host_density(g);
  double wall_now = 0, before_wall = 0;
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j) {
      wall_now += rho[size_t(d.cell(wall, j, k))];
      for (int i = wall - 4; i < wall; ++i) before_wall += rho[size_t(d.cell(i, j, k))];
    }
  EXPECT_LT(run.worst, 1e-6);
  EXPECT_GE(run.lo, 0.f) << "paths along an axis never cross";
  EXPECT_NEAR(wall_now, wall_mass, 1e-6);
  EXPECT_GT(before_wall, 0.9 * 30 * 16 * 2 * 0.6) << "the paint piled against the wall";
  std::printf("[ wall ] 20 cells a step into a wall: density in [%.2e, %.2f], mass change %.2e\n", run.lo, run.hi,
              run.worst);
}

TEST_F(GridStepTest, TracesInAFastFlowDoNotSetThePaintsReach) {
  TileStore canvas(device_, CanvasDims{128, 128, 16});
  GridParams p;
  Grid g(canvas, p, Int3{64, 48, 8}, Int3{0, 0, 0});
  const GridDims d = g.dims();
  // A block of paint in a slow drag (0.31 cells a step along x), and beside it, where the
  // bristles sweep at 6 cells a step, cells holding 1e-9 of a cell: what a drained cell keeps.
  const float trace = 1e-9f, dt = 1.f / 64.f, slow = 20.f, fast = 384.f;
  paint_cells(g, [&](int i, int j, int k) {
    if (k >= 3) return 0.f;
    if (i >= 8 && i < 20 && j >= 16 && j < 28) return 1.f;
    return (i >= 8 && i < 40 && j >= 32 && j < 36) ? trace : 0.f;
  });
  std::vector<float> u(size_t(d.nu()), slow), v(size_t(d.nv()), 0.f), w(size_t(d.nw()), 0.f);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 32; j < 36; ++j)
      for (int i = 0; i <= d.nx; ++i) u[size_t(d.uidx(i, j, k))] = fast;
  const Vec3 c0 = centroid(d, host_density(g));
  const int steps = 6;
  const FlowRun run = advect_in_flow(g, u, v, w, dt, steps, [&](int s) {
    EXPECT_NEAR(g.stats().advect_courant, slow * dt, 1e-4f) << "step " << s << ": the block's reach, not the traces'";
  });
  EXPECT_LT(run.worst, 1e-6) << "the traces' paint is kept too";
  EXPECT_GE(run.lo, 0.f);
  // The traces moved as far as the block's reach lets them in a step and stayed traces.
  const auto rho = host_density(g);
  double traces = 0.0;
  float trace_max = 0.f;
  for (int k = 0; k < d.nz; ++k)
    for (int j = 32; j < 36; ++j)
      for (int i = 0; i < d.nx; ++i) {
        traces += rho[size_t(d.cell(i, j, k))];
        trace_max = std::max(trace_max, rho[size_t(d.cell(i, j, k))]);
      }
  EXPECT_NEAR(traces, 32.0 * 4 * 3 * trace, 1e-3 * 32.0 * 4 * 3 * trace);
  EXPECT_LT(trace_max, 1e-6f);
  // The block is carried its whole way.
  std::vector<float> block(rho);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 32; j < 36; ++j)
      for (int i = 0; i < d.nx; ++i) block[size_t(d.cell(i, j, k))] = 0.f;
  EXPECT_NEAR(centroid(d, block).x - c0.x, slow * dt * float(steps), 0.05f);
  std::printf("[ passes ] traces of %.0e in a flow of %.1f cells a step: the block's reach; traces at most %.2e\n",
              double(trace), fast * dt, double(trace_max));
}

TEST_F(GridStepTest, SwirlKeepsMassAndBoundsAndTurnsThePaint) {
  TileStore canvas(device_, CanvasDims{128, 128, 16});
  GridParams p;
  Grid g(canvas, p, Int3{48, 48, 4}, Int3{0, 0, 0});
  const GridDims d = g.dims();
  // A bar of paint off the centre, in a rigid swirl about the window's axis at omega rad/s.
  // The face velocities come from a stream function on the cell edges, so the discrete flow is
  // divergence-free: u = d psi / dy, v = -d psi / dx with psi = -omega r^2 / 2.
  const float cx = 24.f, cy = 24.f, omega = 6.f;
  paint_cells(g, [&](int i, int j, int) { return (i >= 30 && i < 40 && j >= 21 && j < 27) ? 1.f : 0.f; });
  auto psi = [&](float x, float y) { return -0.5f * omega * ((x - cx) * (x - cx) + (y - cy) * (y - cy)); };
  std::vector<float> u(size_t(d.nu()), 0.f), v(size_t(d.nv()), 0.f), w(size_t(d.nw()), 0.f);
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i <= d.nx; ++i) u[size_t(d.uidx(i, j, k))] = psi(float(i), float(j + 1)) - psi(float(i), float(j));
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j <= d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) v[size_t(d.vidx(i, j, k))] = -(psi(float(i + 1), float(j)) - psi(float(i), float(j)));
  const float dt = p.dt;
  const int steps = 20;  // 2 rad: a third of a turn
  float most = 0.f;
  const FlowRun run = advect_in_flow(g, u, v, w, dt, steps, [&](int) { most = std::max(most, g.stats().advect_courant); });
  const Vec3 c1 = centroid(d, host_density(g));
  const float turned = std::atan2(c1.y - cy, c1.x - cx), expected = omega * dt * float(steps);
  EXPECT_LT(run.worst, 1e-6);
  EXPECT_GE(run.lo, -1e-7f) << "round-off only";
  EXPECT_LE(run.hi, 1.f + 1e-5f) << "a divergence-free flow makes no new maximum";
  EXPECT_NEAR(turned, expected, 0.1f);
  std::printf("[ mass ] swirl %.1f rad: worst relative mass change %.2e, density in [%.2e, %.6f], turned %.3f rad, "
              "outflow Courant number at most %.2f\n",
              expected, run.worst, run.lo, run.hi, turned, most);
}

}  // namespace wb::test
