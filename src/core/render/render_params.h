// Rendering parameters (paper §6 "Liquid rendering"): one POD passed by value to the ray-cast
// kernels. Distances are in cells (1 cell = 0.2 mm); directions in canvas coordinates with
// z up (the canvas surface is z = 0, paint occupies z >= 0).
#pragma once
#include "core/math/vec.h"

namespace wb {

struct RenderParams {
  // Ray marching (§6: "every one quarter of the density grid size").
  float step = 0.25f;             ///< march step along the ray, cells
  float threshold = 0.5f;         ///< surface at this density (volume fraction)
  float normal_eps = 0.5f;        ///< central-difference offset of the density gradient, cells
  // Transparency: oil density sets how far below the surface pigment is still gathered.
  float penetration_per_oil = 6.f;  ///< penetration distance L = oil * this, cells
  float penetration_step = 0.75f;   ///< spacing of the pigment samples below the surface, cells
  // Films: paint whose column never reaches the threshold lies at the column's paint volume.
  float film_fade = 0.25f;   ///< densest cell from threshold to threshold + this: film gives way to the threshold surface
  float film_hiding = 0.2f;  ///< film thickness hiding all but 2 % of the ground (Beer–Lambert), cells (0.04 mm)
  // Ambient occlusion (§6: 64 rays, maximum density reached within a short distance).
  int ao_rays = 64;
  float ao_length = 4.f;    ///< how far each AO ray looks, cells
  float ao_step = 1.f;      ///< AO ray sample spacing, cells (coarse: AO is the cost)
  float ao_offset = 0.75f;  ///< AO rays start this far out along the normal
  float ao_strength = 0.9f; ///< 0 = no occlusion, 1 = fully occluded ray gives black ambient
  // Lighting: one directional light plus ambient; specular for wet paint.
  Vec3 light_dir = Vec3(-0.4f, -0.5f, 0.77f);  ///< towards the light (normalised by the renderer)
  float ambient = 0.45f;
  float diffuse = 0.65f;
  float specular = 0.35f;     ///< Blinn-Phong strength at dryness 0; fades linearly to 0 at dryness 1
  float shininess = 40.f;
  // The primed canvas where there is no paint.
  Vec3 paper_rgb = Vec3(0.93f, 0.91f, 0.86f);
  Vec3 paper_ryb = Vec3(0.f, 0.f, 0.f);  ///< paper as pigment for glazes; set by the renderer from paper_rgb
  Vec3 background_rgb = Vec3(0.16f, 0.16f, 0.17f);  ///< outside the canvas
};

}  // namespace wb
