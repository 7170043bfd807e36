// Particle <-> window grid (paper §4.3, Eq. 11): MAC sampling, rasterisation of mass and
// momentum, and the mixed FLIP/PIC velocity update.
#include <random>

#include "backend_fixture.h"
#include "core/exec/algorithms.h"
#include "core/particles/particle_store.h"
#include "core/math/trilinear.h"
#include "core/particles/particles.h"

namespace wb::test {

class FlipTest : public BackendTest {
 protected:
  static constexpr int nx = 24, ny = 20, nz = 12;
  static constexpr int ox = 1000, oy = 500, oz = 0;
  // Linear field components on their faces: u = 3 + 0.5 x - 0.25 y + 2 z, etc.
  static float lin(int c, float x, float y, float z) {
    return c == 0 ? 3.f + 0.5f * x - 0.25f * y + 2.f * z
                  : (c == 1 ? -1.f + 0.1f * x + 0.3f * y - 0.2f * z : 0.7f - 0.6f * x + 0.05f * y + 0.4f * z);
  }
  static std::vector<float> face_field(int c, bool linear, float uniform) {
    const int ex = nx + (c == 0), ey = ny + (c == 1), ez = nz + (c == 2);
    std::vector<float> f(size_t(ex) * ey * ez);
    for (int k = 0; k < ez; ++k)
      for (int j = 0; j < ey; ++j)
        for (int i = 0; i < ex; ++i) {
          const float x = float(i) + (c == 0 ? 0.f : 0.5f), y = float(j) + (c == 1 ? 0.f : 0.5f),
                      z = float(k) + (c == 2 ? 0.f : 0.5f);
          f[(size_t(k) * ey + j) * ex + i] = linear ? lin(c, x, y, z) : uniform;
        }
    return f;
  }
  ParticleHost random_particles(int n, unsigned seed, float margin) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    ParticleHost h;
    h.resize(size_t(n));
    for (int i = 0; i < n; ++i) {
      h.x[i] = Vec3(ox + margin + (nx - 2 * margin) * U(rng), oy + margin + (ny - 2 * margin) * U(rng),
                    oz + margin + (nz - 2 * margin) * U(rng));
      h.v[i] = Vec3(400.f * U(rng) - 200.f, 400.f * U(rng) - 200.f, 100.f * U(rng) - 50.f);
      h.m[i] = 1e-9f * (0.5f + U(rng));
    }
    return h;
  }
};

TEST_F(FlipTest, MacSamplingReproducesUniformAndLinearFields) {
  std::vector<float> lf[3], uf[3];
  for (int c = 0; c < 3; ++c) lf[c] = face_field(c, true, 0.f), uf[c] = face_field(c, false, 1.5f - c);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  for (int s = 0; s < 2000; ++s) {
    // Linear: exact where every stencil node exists (half a cell in from the edges).
    const Vec3 q(0.5f + (nx - 1) * U(rng), 0.5f + (ny - 1) * U(rng), 0.5f + (nz - 1) * U(rng));
    const Vec3 v = sample_mac(lf[0].data(), lf[1].data(), lf[2].data(), nx, ny, nz, q);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], lin(c, q.x, q.y, q.z), 1e-4f) << c;
    // Uniform: exact anywhere, even outside the window (clamped).
    const Vec3 qa(-3.f + (nx + 6) * U(rng), -3.f + (ny + 6) * U(rng), -3.f + (nz + 6) * U(rng));
    const Vec3 w = sample_mac(uf[0].data(), uf[1].data(), uf[2].data(), nx, ny, nz, qa);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(w[c], 1.5f - c, 1e-6f);
  }
}

namespace {
/// Sums of a raster field on the host: the pairs' first and second members.
std::pair<double, double> pair_sums(const DeviceBuffer<FloatPair>& f) {
  double a = 0.0, b = 0.0;
  for (const FloatPair& p : f.to_host()) a += p.first, b += p.second;
  return {a, b};
}
}  // namespace

TEST_F(FlipTest, RasterisationConservesMassAndMomentum) {
  ParticleStore store(device_);
  store.append(random_particles(20000, 11, 0.f));  // up to the window's edges
  const ParticleHost h = store.to_host();
  const int64_t ncell = int64_t(nx) * ny * nz;
  DeviceBuffer<FloatPair> cell(device_, ncell), face[3];
  ParticleRasterView g{cell.data(), {}, nx, ny, nz, ox, oy, oz};
  cell.fill_zero();
  for (int c = 0; c < 3; ++c) {
    const int64_t nf = int64_t(nx + (c == 0)) * (ny + (c == 1)) * (nz + (c == 2));
    face[c] = DeviceBuffer<FloatPair>(device_, nf);
    face[c].fill_zero();
    g.face[c] = face[c].data();
  }
  particles_rasterise(device_, store.view(), g);
  double m_sum = 0.0, oil_sum = 0.0, p_sum[3] = {0.0, 0.0, 0.0};
  for (size_t k = 0; k < h.size(); ++k) {
    m_sum += h.m[k];
    oil_sum += double(h.m[k]) * h.oil[k];
    for (int c = 0; c < 3; ++c) p_sum[c] += double(h.m[k]) * h.v[k][c];
  }
  EXPECT_NEAR(pair_sums(cell).first, m_sum, 1e-6 * m_sum);
  EXPECT_NEAR(pair_sums(cell).second, oil_sum, 1e-6 * m_sum);
  for (int c = 0; c < 3; ++c) {
    const auto [weight, momentum] = pair_sums(face[c]);
    EXPECT_NEAR(weight, m_sum, 1e-6 * m_sum) << c;
    double p_abs = 0.0;
    for (size_t k = 0; k < h.size(); ++k) p_abs += double(h.m[k]) * std::fabs(h.v[k][c]);
    EXPECT_NEAR(momentum, p_sum[c], 1e-6 * p_abs) << c;
  }
  // A particle outside the window adds nothing.
  ParticleStore out(device_);
  ParticleHost one = random_particles(1, 5, 0.f);
  one.x[0] = Vec3(ox - 3.f, oy + 2.f, 1.f);
  out.append(one);
  particles_rasterise(device_, out.view(), g);
  EXPECT_NEAR(pair_sums(cell).first, m_sum, 1e-6 * m_sum);
  // The cells alone: the same cell sums.
  DeviceBuffer<FloatPair> alone(device_, ncell);
  alone.fill_zero();
  particles_rasterise(device_, store.view(), ParticleRasterView{alone.data(), {}, nx, ny, nz, ox, oy, oz});
  EXPECT_NEAR(pair_sums(alone).first, m_sum, 1e-6 * m_sum);
}

TEST_F(FlipTest, RasterIsEveryParticlesSplatWhateverTheirOrder) {
  // Each node of the four fields against a splat per particle summed on the host in double, for
  // the particles as they come and sorted by cell (runs of particles sharing a stencil summed
  // before their atomic adds), with a cluster of 400 particles in one cell for long runs.
  ParticleHost h = random_particles(6000, 21, 0.f);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  for (int i = 0; i < 400; ++i) {
    h.x.push_back(Vec3(ox + 7.2f + 0.5f * U(rng), oy + 3.1f + 0.3f * U(rng), oz + 5.6f + 0.35f * U(rng)));
    h.v.push_back(Vec3(10.f, -20.f, 5.f));
    h.m.push_back(2e-9f);
    h.pigment_r.push_back(0.f), h.pigment_y.push_back(0.f), h.pigment_b.push_back(0.f);
    h.oil.push_back(0.25f), h.dryness.push_back(0.f);
  }
  for (size_t k = 0; k < h.size(); ++k) h.oil[k] = 0.1f + 0.8f * float(k % 9) / 8.f;
  const int e[4][3] = {{nx, ny, nz}, {nx + 1, ny, nz}, {nx, ny + 1, nz}, {nx, ny, nz + 1}};
  const float off[4][3] = {{0.5f, 0.5f, 0.5f}, {0.f, 0.5f, 0.5f}, {0.5f, 0.f, 0.5f}, {0.5f, 0.5f, 0.f}};
  std::vector<std::pair<double, double>> ref[4];
  double scale = 0.0;
  for (int f = 0; f < 4; ++f) {
    ref[f].assign(size_t(e[f][0]) * e[f][1] * e[f][2], {0.0, 0.0});
    for (size_t k = 0; k < h.size(); ++k) {
      const Vec3 q(h.x[k].x - ox, h.x[k].y - oy, h.x[k].z - oz);
      const Stencil1 sx = stencil1(q.x, off[f][0], e[f][0]), sy = stencil1(q.y, off[f][1], e[f][1]);
      const Stencil1 sz = stencil1(q.z, off[f][2], e[f][2]);
      const double b = f == 0 ? double(h.m[k]) * h.oil[k] : double(h.m[k]) * h.v[k][f - 1];
      for (int n = 0; n < 8; ++n) {
        const double w = double(n & 1 ? sx.w1 : 1.f - sx.w1) * double((n >> 1) & 1 ? sy.w1 : 1.f - sy.w1) *
                         double(n >> 2 ? sz.w1 : 1.f - sz.w1);
        const int64_t node = (int64_t(n >> 2 ? sz.i1 : sz.i0) * e[f][1] + ((n >> 1) & 1 ? sy.i1 : sy.i0)) * e[f][0] +
                             (n & 1 ? sx.i1 : sx.i0);
        ref[f][size_t(node)].first += w * h.m[k];
        ref[f][size_t(node)].second += w * b;
        scale = std::max(scale, std::fabs(w * b));
      }
    }
  }
  ParticleStore store(device_);
  store.append(h);
  Workspace ws(device_);
  for (int sorted = 0; sorted < 2; ++sorted) {
    if (sorted) store.sort_by_cell(Int3{ox, oy, oz}, Int3{nx, ny, nz}, ws);
    DeviceBuffer<FloatPair> fields[4];
    ParticleRasterView g{nullptr, {}, nx, ny, nz, ox, oy, oz};
    for (int f = 0; f < 4; ++f) {
      fields[f] = DeviceBuffer<FloatPair>(device_, int64_t(ref[f].size()));
      fields[f].fill_zero();
      (f == 0 ? g.cell : g.face[f - 1]) = fields[f].data();
    }
    particles_rasterise(device_, store.view(), g);
    for (int f = 0; f < 4; ++f) {
      const std::vector<FloatPair> got = fields[f].to_host();
      double m_max = 0.0;
      for (const auto& r : ref[f]) m_max = std::max(m_max, r.first);
      for (size_t i = 0; i < got.size(); ++i) {
        ASSERT_NEAR(got[i].first, ref[f][i].first, 2e-6 * m_max) << "sorted " << sorted << " field " << f << " node " << i;
        ASSERT_NEAR(got[i].second, ref[f][i].second, 2e-6 * 400 * scale) << "sorted " << sorted << " field " << f;
      }
    }
  }
}

TEST_F(FlipTest, FaceVelocityOfAUniformFlowIsThatFlow) {
  ParticleStore store(device_);
  ParticleHost h = random_particles(5000, 12, 0.f);
  const Vec3 U(120.f, -45.f, 7.5f);
  std::fill(h.v.begin(), h.v.end(), U);
  store.append(h);
  DeviceBuffer<FloatPair> cell(device_, int64_t(nx) * ny * nz), face[3];
  DeviceBuffer<float> vel[3];
  ParticleRasterView g{cell.data(), {}, nx, ny, nz, ox, oy, oz};
  cell.fill_zero();
  float* vp[3];
  for (int c = 0; c < 3; ++c) {
    const int64_t nf = int64_t(nx + (c == 0)) * (ny + (c == 1)) * (nz + (c == 2));
    face[c] = DeviceBuffer<FloatPair>(device_, nf);
    vel[c] = DeviceBuffer<float>(device_, nf);
    face[c].fill_zero();
    g.face[c] = face[c].data();
    vp[c] = vel[c].data();
  }
  particles_rasterise(device_, store.view(), g);
  particles_face_velocity(device_, g, vp[0], vp[1], vp[2], -999.f);
  for (int c = 0; c < 3; ++c) {
    const auto v = vel[c].to_host();
    const auto w = face[c].to_host();
    int filled = 0;
    for (size_t f = 0; f < v.size(); ++f) {
      if (w[f].first > 0.f) {
        ASSERT_NEAR(v[f], U[c], 1e-5f * std::fabs(U[c]) + 1e-6f) << c << " face " << f;
        ++filled;
      } else {
        ASSERT_EQ(v[f], -999.f);
      }
    }
    EXPECT_GT(filled, int(v.size()) * 9 / 10);
  }
}

TEST_F(FlipTest, FlipPicLimits) {
  ParticleHost h = random_particles(3000, 13, 0.f);
  ParticleStore store(device_);
  std::vector<float> lf[3], uf[3];
  DeviceBuffer<float> dl[3], du[3];
  for (int c = 0; c < 3; ++c) {
    lf[c] = face_field(c, true, 0.f);
    uf[c] = face_field(c, false, 10.f * (c + 1));
    dl[c] = DeviceBuffer<float>(device_, lf[c].size());
    du[c] = DeviceBuffer<float>(device_, uf[c].size());
    dl[c].copy_from_host(lf[c]);
    du[c].copy_from_host(uf[c]);
  }
  const MacView linear{dl[0].data(), dl[1].data(), dl[2].data(), nx, ny, nz, ox, oy, oz};
  const MacView uniform{du[0].data(), du[1].data(), du[2].data(), nx, ny, nz, ox, oy, oz};
  auto run = [&](const MacView& before, const MacView& after, float gamma) {
    store.clear();
    store.append(h);
    particles_flip_pic(device_, store.view(), before, after, gamma);
    return store.to_host();
  };
  // u_bar = u: FLIP (gamma = 0) keeps the particle velocity, PIC (gamma = 1) takes the grid's.
  const ParticleHost flip = run(linear, linear, 0.f);
  const ParticleHost pic = run(linear, linear, 1.f);
  for (size_t k = 0; k < h.size(); ++k) {
    const Vec3 q(h.x[k].x - ox, h.x[k].y - oy, h.x[k].z - oz);
    const Vec3 grid = sample_mac(lf[0].data(), lf[1].data(), lf[2].data(), nx, ny, nz, q);
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(flip.v[k][c], h.v[k][c], 1e-4f * std::fabs(h.v[k][c]) + 1e-4f);
      ASSERT_NEAR(pic.v[k][c], grid[c], 1e-4f * std::fabs(grid[c]) + 1e-4f);
    }
  }
  // A uniform projected field is reproduced exactly by PIC, and FLIP adds its change.
  const ParticleHost pic_u = run(linear, uniform, 1.f);
  const ParticleHost mix = run(uniform, uniform, 0.8f);
  for (size_t k = 0; k < h.size(); ++k)
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(pic_u.v[k][c], 10.f * (c + 1), 1e-5f * 10.f * (c + 1));  // to float rounding
      ASSERT_NEAR(mix.v[k][c], 0.8f * 10.f * (c + 1) + 0.2f * h.v[k][c], 1e-3f);
    }
  EXPECT_THROW(particles_flip_pic(device_, store.view(), linear, uniform, 1.5f), Error);
}

}  // namespace wb::test
