// A synthetic layered head for tests and benchmarks: three concentric icosphere wraps (skin,
// muscle, skull wrap) sharing one triangulation, prisms between them split into three tets,
// a skull sphere inside tied to the skull wrap by connecting tets, split into cranium and jaw,
// and a finer skin sphere S embedded barycentrically in the soft tissue layer: the same
// structure the layered head model has, with known geometry.
#pragma once

#include "sim/mesh.h"

namespace softdeca::sim {

struct SyntheticHeadOptions {
  int subdivisions = 2;       // wraps: icosahedron refined this often (20 * 4^k faces)
  int skin_subdivisions = 3;  // S
  double skin_radius = 0.10, muscle_radius = 0.085, skull_wrap_radius = 0.075, skull_radius = 0.07;
  double skin_depth = 0.25;   // S sits this fraction of the soft layer below the skin wrap
  double jaw_below = -0.35;   // skull vertices with y < jaw_below * skull_radius form the jaw
  bool pin_bones = true;
  int landmark_stride = 0;    // > 0: one landmark (a triangle centroid of S) every this many S triangles
};

SimulationMesh synthetic_layered_head(const SyntheticHeadOptions& options);

// Icosahedron refined `levels` times, on the unit sphere.
void icosphere(int levels, Positions& vertices, TriIndices& triangles);

// Prisms between two wraps with the same triangulation (inner index = outer index + offset),
// split into three tets each, conforming across prisms, positively oriented.
TetIndices split_prisms(const Positions& x, const TriIndices& outer, int32_t inner_offset);

}  // namespace softdeca::sim
