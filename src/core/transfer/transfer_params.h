// Parameters of the liquid transfer stage (paper §5.1-5.2, Eq. 12-16, Table 1). One POD,
// passed by value to the stage drivers. Units: lengths in canvas cells (1 cell = 0.2 mm),
// mass in kg, velocity in cells/s. Grid density is a volume fraction: a cell holding
// density rho holds rho * rho0 * cell^3 kg (8e-9 kg for a full cell).
#pragma once
#include <math.h>

namespace wb {

struct TransferParams {
  // --- units (§5.1) ---
  /// Reference paint density rho0. Default 1000 kg/m^3. §5.1 ("rho0 = 1.0e3 kg/m^3").
  float rho0 = 1000.f;
  /// Edge of one grid cell. Default 2e-4 m (0.2 mm). DESIGN "Units and scale".
  float cell_size = 2e-4f;

  // --- bristle capacity (Eq. 12-13) ---
  /// Compression weight mu of Eq. 12: M' = max((1 - mu psi) M_max, M_min). Default 0.5,
  /// range [0, 1]. Table 1.
  float mu = 0.5f;
  /// Largest capacity of one sample, kg. Default rho0 (4/3) pi (0.75 cells)^3 = 1.4137e-8 kg:
  /// a sphere of three bristle radii (0.25 cells each, BrushSpec::bristle_radius) around each
  /// sample; 128 samples x 200 bristles then hold 0.36 ml. Range (0, 1e-5]. Eq. 12.
  float M_max = 1.4137167e-8f;
  /// The bristle radius, cells, that M_max and M_min are given for: a brush of thicker bristles
  /// (clumps) holds (r / kCapacityRadius)^3 times more per sample (for_bristle_radius).
  static constexpr float kCapacityRadius = 0.25f;
  /// Smallest capacity of one sample, kg. Default M_max / 4; with mu = 0.5 and psi <= 1 it only
  /// bites for mu > 0.75. Range [0, M_max]. Eq. 12.
  float M_min = 3.5342917e-9f;
  /// Emission threshold epsilon: a sample emits once m > (1 + epsilon) M. Default 0.1,
  /// range [0, 10]. Table 1, §5.1.
  float epsilon = 0.1f;
  /// Density (volume fraction) at and above which the window's paint is a surface for r_j of
  /// Eq. 13 (grid liquid or dried paint). Default 0.5, range (0, 1].
  float surface_density = 0.5f;
  /// Step of the downward march that finds r_j, cells. Default 0.25, range [0.05, 1].
  float march_step = 0.25f;

  // --- wicking along the bristles (beyond the paper: docs/TRANSFER.md "Wicking") ---
  /// Conductance k of the capillary flow between neighbouring samples of one bristle, 1/s:
  /// the flux on an edge is k dt min(M_a, M_b) (s_a - s_b) with saturation s = m / M (Eq. 13's
  /// capacity), solved implicitly per bristle. The paint a sliding contact sample leaves (swept
  /// contact) is refilled from the rest of its bristle, so a loaded brush keeps painting until it
  /// runs dry. Diffusion length sqrt(2 k t) samples: 63 in 1 s at the default 2000. 0 turns
  /// wicking off (the paper's model). Range [0, 1e6].
  float wick_rate = 2000.f;
  /// Drag pumping, per cell slid: the surface sliding under a bristle shears the paint around
  /// its contact and draws paint along the bristle towards it. Added to the conductance of an
  /// edge as k_slide * (distance the two samples slid over the step, mean), so the supply to
  /// the contact per cell of stroke is the same at any speed (docs/TRANSFER.md "Wicking").
  /// Diffusion length sqrt(2 k_slide L) samples after L cells slid: 14 samples per cell at the
  /// default 100. 0 leaves only the capillary flow. Range [0, 1e5].
  float wick_slide = 100.f;

  // --- swept contact (beyond the paper: docs/TRANSFER.md "Swept contact") ---
  /// Share of the paint a bristle sample sweeps over a surface that stays on the surface (film
  /// splitting: a liquid film between two separating surfaces divides about equally). The sample
  /// leaves split * rho0 * A(R_m, r) * (distance slid): A is the segment of its paint sphere
  /// (radius R_m of its load) that the surface r cells below cuts off, the cap of Eq. 13.
  /// Default 0.5 (a liquid film between two parting surfaces divides about equally), range
  /// [0, 1]; 0 gives the paper's model (paint leaves only through Eq. 13).
  float split = 0.5f;

  // --- dipping (beyond the paper: docs/TRANSFER.md "Dipping") ---
  /// How deep the brush is pushed into a well of paint on the palette, tip first, as a share of
  /// its bristles' length: samples within this height of the tuft's lowest tip go into the pile.
  /// Default 0.5 (the painter's rule: load no more than half the bristles, never up to the
  /// ferrule). Range [0, 1].
  float dip_depth = 0.5f;
  /// Share of a sample's paint that the pile's paint replaces at the tip of an outer bristle,
  /// where the pile is all that touches it: pushing the tuft in scrapes its outside and tip and
  /// presses the new paint in. Less higher up (linearly to 0 at dip_depth) and towards the tuft's
  /// axis (a third there). Default 1, range [0, 1]; 0 only tops up (the paper's dirty brush).
  float dip_exchange = 1.f;

  // --- bristle <-> particle (§5.1) ---
  /// Most particles one sample absorbs per step. Default 8, range [0, 1024]. §5.1 ("a limit on
  /// the maximum number of particles that can be absorbed or emitted by a sample per time step").
  int absorb_limit = 8;
  /// Most particles one sample emits per step. Default 4, range [0, 64]. §5.1.
  int emit_limit = 4;
  /// Largest mass of one emitted particle, kg: a sample emits ceil(excess / emit_mass) particles
  /// (at most emit_limit) of excess / n each. Default 1e-9 kg = rho0 (cell/2)^3. Range (0, M_max].
  float emit_mass = 1e-9f;
  /// Points in the fixed emission pattern (lower half-ball of radius R_j, canvas -z).
  /// Default 16, range [1, 64]. §5.1, Figure 10.
  int emit_pattern = 16;
  /// Colour bleeding of a particle within R_j that is not absorbed: e = bleed min(m_k, m_j) of
  /// each one's colour is mixed into the other (Algorithm 2), masses unchanged. Default 0.1 per
  /// step, range [0, 1]. §5.1 ("colour bleeding").
  float bleed = 0.1f;

  // --- grid <-> particle (§5.2) ---
  /// Half-width of the tent kernel W of Eq. 15-16, cells. W is normalised over the liquid cells
  /// it touches, so the density removed or added equals the particle mass exactly. Default 1
  /// (cloud-in-cell), range [0.5, 2]. Eq. 15-16.
  float kernel_h = 1.f;
  /// A particle moves back to the grid (Eq. 16) when slower than this, cells/s, and farther than
  /// D0 from the bristles. Default 10 cells/s (2 mm/s), range [0, 1e4]. §5.2.
  float slow_speed = 10.f;
  /// Hysteresis of the D0 test, cells: cells within D0 become particles (Eq. 15), particles go
  /// back (Eq. 16) only beyond D0 + return_margin. Without it the kernel of Eq. 16 spreads a
  /// particle just beyond D0 into cells within D0, which turn into particles again the next
  /// step: a shell of paint converted both ways every step. Default 8 cells (two distance
  /// blocks), range [0, 100]. §5.2.
  float return_margin = 8.f;
  /// Cells with less density than this are not sampled into particles. Default 1e-3, range [0, 1].
  float min_cell_density = 1e-3f;
  /// Candidates per cell axis of the stratified sampling of Eq. 15: a cell within D0 gives up
  /// to split^3 particles a step. Default 3 (the paper's 27), range [1, 3]. §5.2.
  int candidate_split = 3;
  /// Block size of the coarse bristle distance field that decides "within D0", cells; the
  /// distance is exact between block centres, so within +-block*sqrt(3) of the true one.
  /// Default 4, range [1, 16]. §5.2.
  int distance_block = 4;

  /// Mass of one full cell, kg: rho0 cell^3 (8e-9 kg by default).
  float cell_mass() const { return rho0 * cell_size * cell_size * cell_size; }
  /// Largest load sphere of a sample (R_j of §5.1 at the largest capacity), cells: a particle
  /// farther than this from every sample is absorbed by none (Eq. 14).
  float absorb_range() const;
  /// These parameters for a brush whose bristles have radius r, cells: a sample's capacity is a
  /// sphere of three bristle radii, so M_max and M_min scale by (r / kCapacityRadius)^3.
  TransferParams for_bristle_radius(float r) const;
};

}  // namespace wb
